// SPDX-License-Identifier: MIT
// Quantized marginal probability-mass tables in the log domain (spec/container.md, "MARG"): the
// codes' meaning and the normative reconstruction. The quantizers are the encoder's
// (codec/encoder/src/bitstream/mass_quantizer.h).
//
// Code 0 is an exact zero; codes 1..2^bits-1 sit evenly in log mass between the table's lo and
// hi (stored as float32, lo rounded down and hi up so every mass lies inside). The decoder
// renormalizes to sum 1, which makes the absolute level irrelevant: only the ratios carry.
#pragma once

#include <cstdint>
#include <vector>

#include "cbrdf/status.h"

namespace cbrdf {

inline constexpr int kMinMarginalBits = 6;
inline constexpr int kMaxMarginalBits = 16;
// Log masses live in [ln(smallest subnormal), 0]; a stored range must too.
inline constexpr double kMinLogMass = -746.0;

struct QuantizedTable {
  float lo = 0.0f;  // log of the smallest nonzero mass, rounded down to float32
  float hi = 0.0f;  // log of the largest mass, rounded up to float32
  std::vector<std::uint32_t> codes;
};

inline std::uint32_t max_code(int bits) {
  return (std::uint32_t{1} << bits) - 1;
}

// Version 1.3 (BASE): the range is stored on a grid of 1/32 in log mass, hi = -H/32 and
// lo = -(H + D)/32 with integers H, D >= 0 (exact in binary32), H + D <= 746 x 32. Coarser than
// binary32 but smaller to code; the step grows by at most 2/32 over the span (0.3% at a span of
// 20).
inline constexpr double kRangeGridUnits = 32.0;
inline constexpr std::uint32_t kMaxGridUnits = 746 * 32;
struct GridRange {
  std::uint32_t hi_units = 0;    // H
  std::uint32_t span_units = 0;  // D
};
// The table's lo and hi for a grid range (codes empty).
QuantizedTable grid_table(const GridRange& range);
// The normative reconstruction. Fails (kCorrupt / kNumeric, message without location) on a code
// above 2^bits-1, a range outside [kMinLogMass, 0] or lo > hi, or weights that underflow to 0.
Expected<std::vector<double>> dequantize_masses(const QuantizedTable& table, int bits);

// Zigzag maps a signed residual to an unsigned one with small magnitudes first.
inline std::uint32_t zigzag(std::int32_t v) {
  return (std::uint32_t(v) << 1) ^ std::uint32_t(v >> 31);
}
inline std::int32_t unzigzag(std::uint32_t u) {
  return std::int32_t(u >> 1) ^ -std::int32_t(u & 1);
}

}  // namespace cbrdf
