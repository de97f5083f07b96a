# SPDX-License-Identifier: MIT
# Finds zstd's source tree for cbrdf.wasm (tools/wasm/CMakeLists.txt) and sets
# CBRDF_ZSTD_SOURCE_DIR to it. The configure never runs apt or reaches the network: the sources
# come from, in order,
#   1. CBRDF_ZSTD_SOURCE_DIR: a source tree (with lib/zstd.h), or a source tarball (Debian's
#      libzstd_*.orig.tar.xz, zstd's own zstd-*.tar.gz, ...) unpacked into <build>/zstd-source;
#   2. a tree already unpacked in <build>/zstd-source (by 1, or by an earlier configure);
#   3. the cache that tools/wasm/fetch-zstd-source.sh fills (tools/scripts/install-deps.sh wasm
#      runs it once): CBRDF_ZSTD_CACHE_DIR, by default $XDG_CACHE_HOME/cbrdf/zstd-source
#      (~/.cache/cbrdf/zstd-source), used in place.
# and otherwise the configure stops, saying how to get them.

set(CBRDF_ZSTD_SOURCE_DIR "" CACHE PATH
    "zstd's source tree or tarball (empty: <build>/zstd-source, then CBRDF_ZSTD_CACHE_DIR)")
if(DEFINED ENV{XDG_CACHE_HOME} AND NOT "$ENV{XDG_CACHE_HOME}" STREQUAL "")
  set(zstd_default_cache "$ENV{XDG_CACHE_HOME}/cbrdf/zstd-source")
else()
  set(zstd_default_cache "$ENV{HOME}/.cache/cbrdf/zstd-source")
endif()
set(CBRDF_ZSTD_CACHE_DIR "${zstd_default_cache}" CACHE PATH
    "Where tools/wasm/fetch-zstd-source.sh keeps zstd's sources (install-deps.sh wasm fills it)")

# The first folder FOLDER or one of its subfolders that holds lib/zstd.h, or "" in out.
function(cbrdf_zstd_tree folder out)
  set(found "")
  if(EXISTS "${folder}/lib/zstd.h")
    set(found "${folder}")
  elseif(IS_DIRECTORY "${folder}")
    file(GLOB subs LIST_DIRECTORIES true "${folder}/*")
    list(SORT subs ORDER DESCENDING)  # the newest release first where several are unpacked
    foreach(sub IN LISTS subs)
      if(EXISTS "${sub}/lib/zstd.h")
        set(found "${sub}")
        break()
      endif()
    endforeach()
  endif()
  set(${out} "${found}" PARENT_SCOPE)
endfunction()

set(zstd_unpacked "${PROJECT_BINARY_DIR}/zstd-source")
set(zstd_tree "")
if(CBRDF_ZSTD_SOURCE_DIR)
  if(IS_DIRECTORY "${CBRDF_ZSTD_SOURCE_DIR}")
    cbrdf_zstd_tree("${CBRDF_ZSTD_SOURCE_DIR}" zstd_tree)
  elseif(EXISTS "${CBRDF_ZSTD_SOURCE_DIR}")
    get_filename_component(zstd_tarball "${CBRDF_ZSTD_SOURCE_DIR}" NAME)
    set(zstd_dest "${zstd_unpacked}/from-tarball")
    # Unpacked again only when the tarball changed: a reconfigure must not rebuild zstd.
    file(SHA256 "${CBRDF_ZSTD_SOURCE_DIR}" zstd_hash)
    set(zstd_stamp "")
    if(EXISTS "${zstd_dest}.sha256")
      file(READ "${zstd_dest}.sha256" zstd_stamp)
    endif()
    if(NOT zstd_stamp STREQUAL zstd_hash)
      file(REMOVE_RECURSE "${zstd_dest}")
      file(MAKE_DIRECTORY "${zstd_dest}")
      execute_process(COMMAND ${CMAKE_COMMAND} -E tar xf "${CBRDF_ZSTD_SOURCE_DIR}"
                      WORKING_DIRECTORY "${zstd_dest}" RESULT_VARIABLE zstd_status
                      ERROR_VARIABLE zstd_error)
      if(NOT zstd_status EQUAL 0)
        message(FATAL_ERROR "cbrdf.wasm: CBRDF_ZSTD_SOURCE_DIR=${CBRDF_ZSTD_SOURCE_DIR} could not "
                            "be unpacked as a tarball: ${zstd_error}")
      endif()
      file(WRITE "${zstd_dest}.sha256" "${zstd_hash}")
    endif()
    cbrdf_zstd_tree("${zstd_dest}" zstd_tree)
  endif()
  if(NOT zstd_tree)
    message(FATAL_ERROR "cbrdf.wasm: CBRDF_ZSTD_SOURCE_DIR=${CBRDF_ZSTD_SOURCE_DIR} is not zstd's "
                        "source (no lib/zstd.h in it or one folder below): give an unpacked source "
                        "tree or a tarball of one (Debian's libzstd_*.orig.tar.xz, zstd's "
                        "zstd-*.tar.gz)")
  endif()
else()
  cbrdf_zstd_tree("${zstd_unpacked}" zstd_tree)
  if(NOT zstd_tree)
    cbrdf_zstd_tree("${CBRDF_ZSTD_CACHE_DIR}" zstd_tree)
  endif()
  if(NOT zstd_tree)
    message(FATAL_ERROR
            "cbrdf.wasm needs zstd's sources, and the configure fetches nothing. Found none in "
            "${zstd_unpacked} nor in CBRDF_ZSTD_CACHE_DIR=${CBRDF_ZSTD_CACHE_DIR}. Either run "
            "tools/wasm/fetch-zstd-source.sh once (Debian's libzstd source package into that "
            "cache; tools/scripts/install-deps.sh wasm runs it), or pass "
            "-DCBRDF_ZSTD_SOURCE_DIR=<an unpacked zstd source tree or its tarball>.")
  endif()
endif()

# The release, for the status line: the wasm and native decoders should share it.
file(STRINGS "${zstd_tree}/lib/zstd.h" zstd_version_lines
     REGEX "^#define ZSTD_VERSION_(MAJOR|MINOR|RELEASE) +[0-9]+")
set(zstd_version "")
foreach(line IN LISTS zstd_version_lines)
  string(REGEX REPLACE "^#define ZSTD_VERSION_[A-Z]+ +([0-9]+).*" "\\1" part "${line}")
  list(APPEND zstd_version "${part}")
endforeach()
list(JOIN zstd_version "." zstd_version)
set(CBRDF_ZSTD_TREE "${zstd_tree}")
set(CBRDF_ZSTD_VERSION "${zstd_version}")
