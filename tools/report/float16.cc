// SPDX-License-Identifier: MIT
#include "report/float16.h"

#include <bit>

namespace cbrdf::report {

std::uint16_t float_to_half(float value) {
  const std::uint32_t f = std::bit_cast<std::uint32_t>(value);
  const std::uint16_t sign = std::uint16_t((f >> 16) & 0x8000u);
  const std::uint32_t abs = f & 0x7FFFFFFFu;
  if (abs >= 0x7F800000u) {  // Inf or NaN
    return std::uint16_t(sign | 0x7C00u | (abs > 0x7F800000u ? 0x0200u : 0u));
  }
  if (abs >= 0x477FF000u) return std::uint16_t(sign | 0x7C00u);  // rounds past 65504
  if (abs < 0x38800000u) {
    // Below the smallest normal half (2^-14): a subnormal, value / 2^-24 rounded to an integer.
    if (abs < 0x33000000u) return sign;  // at most half the smallest subnormal: ties to even zero
    const std::uint32_t mantissa = (abs & 0x007FFFFFu) | 0x00800000u;
    const int shift = 126 - int(abs >> 23);  // 14..24 for exponents 112..102
    const std::uint32_t q = mantissa >> shift;
    const std::uint32_t rest = mantissa & ((1u << shift) - 1u);
    const std::uint32_t halfway = 1u << (shift - 1);
    const std::uint32_t rounded = q + ((rest > halfway || (rest == halfway && (q & 1u))) ? 1u : 0u);
    return std::uint16_t(sign | rounded);  // a carry into bit 10 makes the smallest normal
  }
  // Normal: rebias the exponent and round the 23-bit mantissa to 10 bits; a carry propagates
  // into the exponent, which is the correct next binade.
  const std::uint32_t rebased = abs - ((127u - 15u) << 23);
  const std::uint32_t q = rebased >> 13;
  const std::uint32_t rest = rebased & 0x1FFFu;
  const std::uint32_t rounded = q + ((rest > 0x1000u || (rest == 0x1000u && (q & 1u))) ? 1u : 0u);
  return std::uint16_t(sign | rounded);
}

float half_to_float(std::uint16_t bits) {
  const std::uint32_t sign = std::uint32_t(bits & 0x8000u) << 16;
  const std::uint32_t exponent = (bits >> 10) & 0x1Fu;
  std::uint32_t mantissa = bits & 0x3FFu;
  if (exponent == 0x1Fu) return std::bit_cast<float>(sign | 0x7F800000u | (mantissa << 13));
  if (exponent != 0) {
    return std::bit_cast<float>(sign | ((exponent + 112u) << 23) | (mantissa << 13));
  }
  if (mantissa == 0) return std::bit_cast<float>(sign);
  // Subnormal: normalize.
  int e = 113;
  while (!(mantissa & 0x400u)) {
    mantissa <<= 1;
    --e;
  }
  return std::bit_cast<float>(sign | (std::uint32_t(e) << 23) | ((mantissa & 0x3FFu) << 13));
}

}  // namespace cbrdf::report
