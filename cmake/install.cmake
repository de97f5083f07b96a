# SPDX-License-Identifier: MIT
# Install: libraries (static and shared), the public headers, a CMake package and
# pkg-config files. The public headers are exactly the files under each layer's include/ (the
# HEADERS file sets below, globbed, so a header put there is installed); everything under src/ is
# internal and never installed. libcbrdf_decoder.a holds the format layer too, so its file set
# carries format's headers and the generated version.h.
file(GLOB CBRDF_DECODER_HEADERS CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/format/include/cbrdf/*.h
     ${PROJECT_SOURCE_DIR}/codec/decoder/include/cbrdf/*.h)
target_sources(cbrdf_decoder PUBLIC FILE_SET HEADERS
  BASE_DIRS ${PROJECT_SOURCE_DIR}/format/include ${PROJECT_SOURCE_DIR}/codec/decoder/include
            ${CBRDF_GENERATED_INCLUDE}
  FILES ${CBRDF_DECODER_HEADERS} ${CBRDF_GENERATED_INCLUDE}/cbrdf/version.h)
if(NOT CBRDF_DECODER_ONLY)
  file(GLOB CBRDF_ENCODER_HEADERS CONFIGURE_DEPENDS
       ${PROJECT_SOURCE_DIR}/codec/encoder/include/cbrdf/*.h)
  target_sources(cbrdf_encoder PUBLIC FILE_SET HEADERS
    BASE_DIRS ${PROJECT_SOURCE_DIR}/codec/encoder/include FILES ${CBRDF_ENCODER_HEADERS})
endif()
if(CBRDF_WITH_EXTRAS)
  file(GLOB CBRDF_EXTRAS_HEADERS CONFIGURE_DEPENDS
       ${PROJECT_SOURCE_DIR}/codec/extras/include/cbrdf/*.h)
  target_sources(cbrdf_extras PUBLIC FILE_SET HEADERS
    BASE_DIRS ${PROJECT_SOURCE_DIR}/codec/extras/include FILES ${CBRDF_EXTRAS_HEADERS})
endif()
set(CBRDF_PUBLIC_HEADERS ${CBRDF_DECODER_HEADERS} ${CBRDF_ENCODER_HEADERS} ${CBRDF_EXTRAS_HEADERS})
# The targets' names in the package (cbrdfConfig.cmake.in lists them), and the same names in the
# build tree for a project that adds cbrdf with add_subdirectory or FetchContent.
set_target_properties(cbrdf_decoder PROPERTIES EXPORT_NAME decoder_static)
add_library(cbrdf::decoder_static ALIAS cbrdf_decoder)
if(CBRDF_SHARED)
  add_library(cbrdf::decoder ALIAS cbrdf_decoder_shared)
endif()
if(NOT CBRDF_DECODER_ONLY)
  add_library(cbrdf::encoder_static ALIAS cbrdf_encoder)
  if(CBRDF_SHARED)
    add_library(cbrdf::encoder ALIAS cbrdf_encoder_shared)
  endif()
endif()
if(CBRDF_WITH_EXTRAS)
  add_library(cbrdf::extras_static ALIAS cbrdf_extras)
endif()
install(TARGETS cbrdf_decoder cbrdf_compression_deps EXPORT cbrdfTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        FILE_SET HEADERS DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
if(CBRDF_SHARED)
  install(TARGETS cbrdf_decoder_shared EXPORT cbrdfTargets
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
endif()
install(EXPORT cbrdfTargets NAMESPACE cbrdf:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/cbrdf)
if(NOT CBRDF_DECODER_ONLY)
  # The measured samples' weights are compiled into libcbrdf_encoder: their licence goes with it.
  install(FILES ${PROJECT_SOURCE_DIR}/data/measured/LICENSE-nbrdf.txt
                ${PROJECT_SOURCE_DIR}/data/measured/README.md
          DESTINATION ${CMAKE_INSTALL_DOCDIR}/measured)
  # The encoder's targets are a component of their own (find_package(cbrdf COMPONENTS encoder)):
  # its static archive needs Ceres, which a decoder user should not have to have.
  set_target_properties(cbrdf_encoder PROPERTIES EXPORT_NAME encoder_static)
  install(TARGETS cbrdf_encoder EXPORT cbrdfEncoderTargets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
          FILE_SET HEADERS DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  if(CBRDF_SHARED)
    install(TARGETS cbrdf_encoder_shared EXPORT cbrdfEncoderTargets
            LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
  endif()
  install(EXPORT cbrdfEncoderTargets NAMESPACE cbrdf::
          DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/cbrdf)
endif()
if(CBRDF_WITH_EXTRAS)
  # Images and analytic fits (find_package(cbrdf COMPONENTS extras)): OpenEXR and libpng besides
  # the encoder's Ceres.
  set_target_properties(cbrdf_extras PROPERTIES EXPORT_NAME extras_static)
  install(TARGETS cbrdf_extras EXPORT cbrdfExtrasTargets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
          FILE_SET HEADERS DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  install(EXPORT cbrdfExtrasTargets NAMESPACE cbrdf::
          DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/cbrdf)
endif()
include(CMakePackageConfigHelpers)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/cbrdfConfig.cmake.in
  ${PROJECT_BINARY_DIR}/cbrdfConfig.cmake INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/cbrdf)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/cbrdfConfigVersion.cmake
  COMPATIBILITY SameMajorVersion)
install(FILES ${PROJECT_BINARY_DIR}/cbrdfConfig.cmake ${PROJECT_BINARY_DIR}/cbrdfConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/cbrdf)
# The pkg-config files: cbrdf-decoder and cbrdf link the shared libraries (with an rpath to a
# non-system libdir; the archives where no shared library is built), cbrdf-decoder-static and
# cbrdf-static the archives (their dependencies in Requires and Libs, as an archive always needs
# them). Written at install time (cmake/install_pkgconfig.cmake), when the prefix is known.
set(CBRDF_PC_FILES cbrdf-decoder cbrdf-decoder-static)
if(NOT CBRDF_DECODER_ONLY)
  list(APPEND CBRDF_PC_FILES cbrdf cbrdf-static)
endif()
set(CBRDF_PC_SYSTEM_LIBDIRS ${CMAKE_C_IMPLICIT_LINK_DIRECTORIES}
    ${CMAKE_CXX_IMPLICIT_LINK_DIRECTORIES} ${CMAKE_PLATFORM_IMPLICIT_LINK_DIRECTORIES})
install(CODE "
set(CBRDF_PC_FILES \"${CBRDF_PC_FILES}\")
set(CBRDF_PC_SOURCE_DIR \"${PROJECT_SOURCE_DIR}/cmake\")
set(CBRDF_PC_BINARY_DIR \"${PROJECT_BINARY_DIR}/pkgconfig\")
set(CBRDF_PC_LIBDIR \"${CMAKE_INSTALL_LIBDIR}\")
set(CBRDF_PC_INCLUDEDIR \"${CMAKE_INSTALL_INCLUDEDIR}\")
set(CBRDF_PC_VERSION \"${PROJECT_VERSION}\")
set(CBRDF_PC_SHARED \"${CBRDF_SHARED}\")
set(CBRDF_PC_SYSTEM_LIBDIRS \"${CBRDF_PC_SYSTEM_LIBDIRS}\")")
install(SCRIPT ${PROJECT_SOURCE_DIR}/cmake/install_pkgconfig.cmake)
