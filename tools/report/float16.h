// SPDX-License-Identifier: MIT
// IEEE 754 binary16 ("half") conversion, for the report's near-lossless float16 storage
// baseline (float16_baseline.h).
//
// float_to_half rounds to nearest, ties to even, exactly as a hardware conversion does: values
// beyond the largest finite half (65504) round to infinity when at least 65520, NaN stays NaN (as a
// quiet NaN keeping the sign), and tiny values become subnormal halves or signed zero.
// half_to_float is exact.
#pragma once

#include <cstdint>

namespace cbrdf::report {

std::uint16_t float_to_half(float value);
float half_to_float(std::uint16_t bits);

}  // namespace cbrdf::report
