// SPDX-License-Identifier: MIT
#include "cbrdf/version.h"

#include "cbrdf/container.h"

// version.h is generated from cmake/version.h.in; the container's version lives in container.h.
static_assert(CBRDF_CONTAINER_VERSION_MAJOR == cbrdf::kContainerMajorVersion &&
                  CBRDF_CONTAINER_VERSION_MINOR == cbrdf::kContainerMinorVersion,
              "cmake/version.h.in and container.h disagree on the container version");

namespace cbrdf {

const char* version_string() {
  return CBRDF_VERSION_STRING;
}

int version() {
  return CBRDF_VERSION;
}

}  // namespace cbrdf
