// SPDX-License-Identifier: MIT
// The parameter domains the file format accepts, shared by encoder and decoder.
#include <cmath>
#include <cstdio>
#include <string>

#include "chunks.h"
#include "copula/copula.h"
#include "copula/registry.h"

namespace cbrdf {

std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// The range a file may hold for each family is the encoder's own search range (its row in
// copula/registry.h), inside the family's mathematical domain (copula.h). Beyond it the dependence
// is so strong that the density no longer changes at the grid's resolution in any way a fit could
// want, and evaluating it takes the slow log-sum paths (spec 4.2, section 7): a file there is
// refused, so none decodes slower than the encoder's own.
bool copula_parameter_valid(CopulaFamily family, double theta) {
  const CopulaFamilyRow* row = family_row(family);
  if (!std::isfinite(theta) || !row) return false;
  return row->copula().in_domain(theta) && theta >= row->search_lo && theta <= row->search_hi;
}

Status check_channel_params(std::uint8_t family, double theta, double scale) {
  const CopulaFamilyRow* row = family_row(CopulaFamily(family));
  if (!row) {
    std::string known;
    for (const CopulaFamilyRow& r : kCopulaFamilies) {
      known += (known.empty() ? "" : ", ") + std::to_string(int(r.id)) + " " + std::string(r.title);
    }
    return error(ErrorCode::kCorrupt,
                 "unknown copula family " + std::to_string(family) + " (known: " + known + ")");
  }
  if (!std::isfinite(theta)) {
    return error(ErrorCode::kNumeric, "parameter " + number_text(theta) + " is not finite");
  }
  if (!copula_parameter_valid(row->id, theta)) {
    return error(ErrorCode::kNumeric, "parameter " + number_text(theta) + " is outside the " +
                                          std::string(row->name) + " domain a file may hold, [" +
                                          number_text(row->search_lo) + ", " +
                                          number_text(row->search_hi) + "]");
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
