// SPDX-License-Identifier: MIT
// The parameter domains the file format accepts, shared by encoder and decoder.
#include <cmath>
#include <cstdio>
#include <string>

#include "cbrdf/copula.h"
#include "chunks.h"

namespace cbrdf {

std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

bool copula_parameter_valid(CopulaFamily family, double theta) {
  // One source of truth for the domains: the copula implementations (copula.h).
  return std::isfinite(theta) && family_valid(std::uint8_t(family)) &&
         copula_for(family).in_domain(theta);
}

Status check_channel_params(std::uint8_t family, double theta, double scale) {
  if (!family_valid(family)) {
    return error(ErrorCode::kCorrupt, "unknown copula family " + std::to_string(family) +
                                          " (known: 0 independence, 1 Frank, 2 Clayton, "
                                          "3 Gumbel, 4 Joe)");
  }
  if (!std::isfinite(theta)) {
    return error(ErrorCode::kNumeric, "parameter " + number_text(theta) + " is not finite");
  }
  if (!copula_parameter_valid(CopulaFamily(family), theta)) {
    const Copula::Domain d = copula_for(CopulaFamily(family)).domain();
    const std::string range = std::string(d.lo_inclusive ? "[" : "(") + number_text(d.lo) + ", " +
                              number_text(d.hi) + (d.hi_inclusive ? "]" : ")");
    return error(ErrorCode::kNumeric, "parameter " + number_text(theta) + " is outside the " +
                                          std::string(family_name(CopulaFamily(family))) +
                                          " domain " + range);
  }
  if (!std::isfinite(scale) || scale < 0.0) {
    return error(ErrorCode::kNumeric,
                 "scale K " + number_text(scale) + " is not a finite value >= 0");
  }
  return ok_status();
}

Status check_trailing(std::size_t trailing, std::uint16_t file_minor) {
  if (trailing == 0 || file_minor > kContainerMinorVersion) return ok_status();
  return error(ErrorCode::kCorrupt,
               std::to_string(trailing) + " unexpected bytes after the payload's last field");
}

}  // namespace cbrdf
