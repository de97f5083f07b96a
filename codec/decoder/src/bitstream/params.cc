// SPDX-License-Identifier: MIT
// The parameter domains the file format accepts, shared by encoder and decoder.
#include <array>
#include <cmath>
#include <cstdio>
#include <string>

#include "chunks.h"
#include "copula/copula.h"
#include "density/grid_copula.h"

namespace cbrdf {

std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

namespace {

constexpr int kFamilies = int(CopulaFamily::kJoe) + 1;

struct ParameterRange {
  double lo = 0, hi = 0;
};

// The range a file may hold for each family: the encoder's own fit range (the bounds its solver
// works within, internal::make_grid_copula), inside the family's mathematical domain (copula.h).
// Beyond it the dependence is so strong that the density no longer changes at the grid's
// resolution in any way a fit could want, and evaluating it takes the slow log-sum paths
// (spec 4.2, section 7): a file there is refused, so none decodes slower than the encoder's own.
const ParameterRange& format_range(CopulaFamily family) {
  static const std::array<ParameterRange, kFamilies> ranges = [] {
    std::array<ParameterRange, kFamilies> r{};
    for (int f = 0; f < kFamilies; ++f) {
      const auto grid = internal::make_grid_copula(CopulaFamily(f));
      r[std::size_t(f)] = {grid->fit_lo(), grid->fit_hi()};
    }
    return r;
  }();
  return ranges[std::size_t(family)];
}

}  // namespace

bool copula_parameter_valid(CopulaFamily family, double theta) {
  if (!std::isfinite(theta) || !family_valid(std::uint8_t(family))) return false;
  const ParameterRange& r = format_range(family);
  return copula_for(family).in_domain(theta) && theta >= r.lo && theta <= r.hi;
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
    const ParameterRange& r = format_range(CopulaFamily(family));
    return error(ErrorCode::kNumeric, "parameter " + number_text(theta) + " is outside the " +
                                          std::string(family_name(CopulaFamily(family))) +
                                          " domain a file may hold, [" + number_text(r.lo) + ", " +
                                          number_text(r.hi) + "]");
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
