# SPDX-License-Identifier: MIT
# `cbrdf view`'s page (viewer/) and cbrdf.wasm + cbrdf.mjs (with the npm package they belong to):
# where the command finds them in the build, and where `cmake --install` puts them
# (<datadir>/cbrdf/viewer and <datadir>/cbrdf/wasm), so that the installed command serves the page
# with no --viewer or --wasm. Included by tools/CMakeLists.txt after the cbrdf_cli target.
include(GNUInstallDirs)

# The wasm builds the command and the install look in, first match wins: CBRDF_WASM_BUILD_DIR,
# the tests' (ctest wasm_build) and the source tree's build-wasm (tools/wasm/README.md).
set(CBRDF_VIEWER_WASM_DIRS ${PROJECT_BINARY_DIR}/wasm-build/wasm ${PROJECT_SOURCE_DIR}/build-wasm/wasm)
if(CBRDF_WASM_BUILD_DIR)
  list(PREPEND CBRDF_VIEWER_WASM_DIRS ${CBRDF_WASM_BUILD_DIR}/wasm)
endif()
# tests/viewer's viewer_installed checks the install against the same list.
set_property(GLOBAL PROPERTY CBRDF_VIEWER_WASM_DIRS ${CBRDF_VIEWER_WASM_DIRS})
set(CBRDF_VIEWER_INSTALL_DIR ${CMAKE_INSTALL_DATADIR}/cbrdf/viewer)
set(CBRDF_VIEWER_WASM_INSTALL_DIR ${CMAKE_INSTALL_DATADIR}/cbrdf/wasm)

# The installed folders relative to the installed command's: the same whatever the prefix given
# to `cmake --install --prefix` (a relocatable install).
file(RELATIVE_PATH viewer_rel ${CMAKE_INSTALL_FULL_BINDIR}
     ${CMAKE_INSTALL_FULL_DATADIR}/cbrdf/viewer)
file(RELATIVE_PATH wasm_rel ${CMAKE_INSTALL_FULL_BINDIR} ${CMAKE_INSTALL_FULL_DATADIR}/cbrdf/wasm)
list(JOIN CBRDF_VIEWER_WASM_DIRS "|" wasm_dirs)
set_property(SOURCE cli/cmd_view.cc APPEND PROPERTY COMPILE_DEFINITIONS
  CBRDF_VIEWER_DIR="${PROJECT_SOURCE_DIR}/viewer" CBRDF_WASM_DIRS="${wasm_dirs}"
  CBRDF_VIEWER_INSTALLED="${viewer_rel}" CBRDF_WASM_INSTALLED="${wasm_rel}")

# The page: what the browser loads (its README is the source tree's documentation).
install(DIRECTORY ${PROJECT_SOURCE_DIR}/viewer/ DESTINATION ${CBRDF_VIEWER_INSTALL_DIR}
        COMPONENT viewer FILES_MATCHING PATTERN "*.html" PATTERN "*.mjs" PATTERN "*.css")
# cbrdf.wasm, cbrdf.mjs and the npm package's other files from the first wasm build that holds the
# two, looked up when installing
# (the wasm is built apart, with Emscripten, possibly after this configure). Without one the
# install goes on and says so; the installed command then names how to build it.
install(CODE "set(cbrdf_wasm_dirs \"${CBRDF_VIEWER_WASM_DIRS}\")
set(cbrdf_wasm_dest \"${CBRDF_VIEWER_WASM_INSTALL_DIR}\")" COMPONENT viewer)
install(CODE [[
  set(cbrdf_wasm_from "")
  foreach(dir IN LISTS cbrdf_wasm_dirs)
    if(EXISTS "${dir}/cbrdf.wasm" AND EXISTS "${dir}/cbrdf.mjs")
      set(cbrdf_wasm_from "${dir}")
      break()
    endif()
  endforeach()
  if(cbrdf_wasm_from)
    # With the rest of the npm package the build staged beside them (tools/npm/README.md): the
    # folder is then the package as `npm pack` packs it.
    set(cbrdf_wasm_files "")
    foreach(name cbrdf.wasm cbrdf.mjs cbrdf.d.ts glsl.mjs glsl.d.ts three.mjs three.d.ts
                 package.json README.md LICENSE LICENSE.zstd)
      if(EXISTS "${cbrdf_wasm_from}/${name}")
        list(APPEND cbrdf_wasm_files "${cbrdf_wasm_from}/${name}")
      endif()
    endforeach()
    file(INSTALL DESTINATION "${CMAKE_INSTALL_PREFIX}/${cbrdf_wasm_dest}" TYPE FILE
         FILES ${cbrdf_wasm_files})
    if(IS_DIRECTORY "${cbrdf_wasm_from}/example")
      file(INSTALL DESTINATION "${CMAKE_INSTALL_PREFIX}/${cbrdf_wasm_dest}" TYPE DIRECTORY
           FILES "${cbrdf_wasm_from}/example")
    endif()
  else()
    list(JOIN cbrdf_wasm_dirs ", " cbrdf_tried)
    message(STATUS "cbrdf view: no cbrdf.wasm and cbrdf.mjs in ${cbrdf_tried}: not installed; "
                   "the installed `cbrdf view` will need --wasm DIR. Build them first "
                   "(tools/wasm/README.md) to install them.")
  endif()
]] COMPONENT viewer)
