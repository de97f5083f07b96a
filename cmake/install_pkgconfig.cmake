# SPDX-License-Identifier: MIT
# Writes and installs the pkg-config files at install time (install(SCRIPT), cmake/install.cmake),
# because only then is the prefix known: `cmake --install --prefix` may differ from the configured
# CMAKE_INSTALL_PREFIX. Where the libdir is not one the linker and the loader search by themselves
# (the toolchain's implicit link directories: /usr/lib, /usr/lib/<multiarch>, /lib...), the shared
# libraries' Libs carry an rpath to it, so that a program built with `pkg-config --libs` runs as
# built, without LD_LIBRARY_PATH; /usr/local/lib is not such a directory (the loader finds it only
# after ldconfig), so it gets one too. Set by install.cmake: CBRDF_PC_FILES, CBRDF_PC_SOURCE_DIR,
# CBRDF_PC_BINARY_DIR, CBRDF_PC_LIBDIR, CBRDF_PC_INCLUDEDIR, CBRDF_PC_VERSION, CBRDF_PC_SHARED,
# CBRDF_PC_SYSTEM_LIBDIRS.
if(IS_ABSOLUTE "${CBRDF_PC_LIBDIR}")
  set(libdir_full "${CBRDF_PC_LIBDIR}")
else()
  set(libdir_full "${CMAKE_INSTALL_PREFIX}/${CBRDF_PC_LIBDIR}")
endif()
cmake_path(NORMAL_PATH libdir_full)
string(REGEX REPLACE "(.)/$" "\\1" libdir_full "${libdir_full}")
set(system_libdir FALSE)
foreach(dir IN LISTS CBRDF_PC_SYSTEM_LIBDIRS)
  cmake_path(NORMAL_PATH dir)
  string(REGEX REPLACE "(.)/$" "\\1" dir "${dir}")
  if(dir STREQUAL libdir_full)
    set(system_libdir TRUE)
  endif()
endforeach()
if(NOT CBRDF_PC_SHARED)
  set(CBRDF_PC_RPATH "")
  set(CBRDF_PC_RPATH_NOTE "# Built without the shared libraries: Libs names the archive.")
elseif(system_libdir)
  set(CBRDF_PC_RPATH "")
  set(CBRDF_PC_RPATH_NOTE "# ${libdir_full} is a system directory: no rpath.")
else()
  set(CBRDF_PC_RPATH " -Wl,-rpath,\${libdir}")
  set(CBRDF_PC_RPATH_NOTE
      "# Libs carries an rpath: ${libdir_full} is not one of the toolchain's own library directories.")
endif()
# Relocatable: the prefix is found from the .pc file's own folder, wherever it was installed.
file(RELATIVE_PATH to_prefix "${libdir_full}/pkgconfig" "${CMAKE_INSTALL_PREFIX}")
string(REGEX REPLACE "/$" "" to_prefix "${to_prefix}")
set(CBRDF_PC_PREFIX "\${pcfiledir}/${to_prefix}")
if(IS_ABSOLUTE "${CBRDF_PC_LIBDIR}")
  set(CBRDF_PC_LIBDIR_VALUE "${CBRDF_PC_LIBDIR}")
else()
  set(CBRDF_PC_LIBDIR_VALUE "\${prefix}/${CBRDF_PC_LIBDIR}")
endif()
if(IS_ABSOLUTE "${CBRDF_PC_INCLUDEDIR}")
  set(CBRDF_PC_INCLUDEDIR_VALUE "${CBRDF_PC_INCLUDEDIR}")
else()
  set(CBRDF_PC_INCLUDEDIR_VALUE "\${prefix}/${CBRDF_PC_INCLUDEDIR}")
endif()
set(PROJECT_VERSION "${CBRDF_PC_VERSION}")
# One folder per destination, so that installs of one build to two prefixes at once do not race.
string(MD5 destination "$ENV{DESTDIR}${libdir_full}")
foreach(pc IN LISTS CBRDF_PC_FILES)
  set(written "${CBRDF_PC_BINARY_DIR}/${destination}/${pc}.pc")
  configure_file("${CBRDF_PC_SOURCE_DIR}/${pc}.pc.in" "${written}" @ONLY)
  file(INSTALL DESTINATION "${libdir_full}/pkgconfig" TYPE FILE FILES "${written}")
endforeach()
