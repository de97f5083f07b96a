// SPDX-License-Identifier: MIT
// RESD modes 3 and 4 (spec 4.6), the writer's side of the level-by-level interpolation
// (bitstream/residual_levels.h): the codes chosen from the residual to code.
#pragma once

#include "bitstream/chunks.h"
#include "bitstream/residual_levels.h"
#include "cbrdf/model.h"

namespace cbrdf::internal {

// The writer's side: `target` holds the residual to code (kMaskBits values, NaN where any value
// will do, e.g. not-measured bins). Sets residual.codes to round((target - prediction) / step),
// clamped to -2^28..2^28 (0 where the target is NaN), and residual.values to the rebuilt values.
inline void quantize_interpolated(const double* target, Residual* residual) {
  residual->codes.assign(kMaskBits, 0);
  interpolate_levels(target, residual);
}

}  // namespace cbrdf::internal
