// SPDX-License-Identifier: MIT
#include "quantize.h"

#include <cmath>
#include <string>

namespace cbrdf {

QuantizedTable grid_table(const GridRange& range) {
  QuantizedTable t;
  t.hi = float(-double(range.hi_units) / kRangeGridUnits);
  t.lo = float(-double(range.hi_units + range.span_units) / kRangeGridUnits);
  return t;
}

Expected<std::vector<double>> dequantize_masses(const QuantizedTable& t, int bits) {
  const std::uint32_t top = max_code(bits);
  std::vector<double> out(t.codes.size(), 0.0);
  if (!std::isfinite(t.lo) || !std::isfinite(t.hi) || double(t.lo) < kMinLogMass || t.hi > 0.0f ||
      t.lo > t.hi) {
    return error(ErrorCode::kNumeric, "log-mass range [" + std::to_string(t.lo) + ", " +
                                          std::to_string(t.hi) +
                                          "] is not an ordered range inside [-746, 0]");
  }
  bool any = false;
  for (std::uint32_t q : t.codes) {
    if (q > top) {
      return error(ErrorCode::kCorrupt, "code " + std::to_string(q) + " exceeds the largest " +
                                            std::to_string(bits) + "-bit code " +
                                            std::to_string(top));
    }
    any = any || q != 0;
  }
  if (!any) return out;
  // Weights relative to the top code (at most 1, so nothing overflows), then renormalized.
  const double span = double(t.hi) - double(t.lo);
  double sum = 0.0;
  for (std::size_t i = 0; i < t.codes.size(); ++i) {
    if (t.codes[i] == 0) continue;
    const double x = (double(t.codes[i]) - double(top)) * span / double(top - 1);
    out[i] = std::exp(x);
    sum += out[i];
  }
  if (!(sum > 0.0) || !std::isfinite(sum)) {
    return error(ErrorCode::kNumeric, "the table's weights underflow to zero");
  }
  for (double& v : out) v /= sum;
  return out;
}

}  // namespace cbrdf
