// SPDX-License-Identifier: MIT
#include "cbrdf/version.h"

namespace cbrdf {

const char* version_string() {
  return CBRDF_VERSION_STRING;
}

int version() {
  return CBRDF_VERSION;
}

}  // namespace cbrdf
