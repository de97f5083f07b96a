// SPDX-License-Identifier: MIT
// RESD mode 3 (spec 4.6): the residual rebuilt level by level, each bin predicted by interpolating
// bins rebuilt before it. One routine serves the reader (codes in, residual out) and the writer
// (residual in, codes and its own rebuilt residual out), so both compute the same binary64 values.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "cbrdf/model.h"
#include "chunks.h"

namespace cbrdf::internal {

// The code of residual r at step `step`: round(r / step) clamped to -2^28..2^28, 0 for NaN (a
// bin whose value does not matter). Modes 0, 2 and 3 alike.
inline std::int32_t residual_code(double r, double step) {
  const double top = double(kMaxResidualCode);
  return r == r ? std::int32_t(std::clamp(std::nearbyint(r / step), -top, top)) : 0;
}

// Modes 3 and 4: the first level (0 the finest .. levels - 1) whose multiplier is outside
// 1..kMaxFineMultiplier or takes its coarsest row's bound (multiplier x max_error x
// 2^max_row_shift) past the format's largest, or -1 when none does. The reader's check and the
// writer's.
inline int level_multiplier_out_of_range(const Residual& r) {
  const double top = std::ldexp(r.max_error, r.max_row_shift());
  for (int l = 0; l < r.levels && l < kMaxResidualLevels; ++l) {
    const int m = r.multiplier_of_level(l);
    if (m < 1 || m > kMaxFineMultiplier || double(m) * top > kMaxResidualError) return l;
  }
  return -1;
}

// Rebuilds residual.values from residual.codes (levels, steps, row shifts and fine multiplier
// taken from `residual`). Codes at not-measured bins are 0 and their values predictions only.
void rebuild_interpolated(Residual* residual);

// The one routine of reader and writer: with `target` null, rebuilds residual.values from
// residual.codes (rebuild_interpolated); else sets each code from target as it goes
// (the encoder's quantize_interpolated, bitstream/residual_levels_writer.h).
void interpolate_levels(const double* target, Residual* residual);

}  // namespace cbrdf::internal
