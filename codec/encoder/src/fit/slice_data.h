// SPDX-License-Identifier: MIT
// One slice of one channel, laid out for fitting: values and mask in [theta_h][theta_d][phi_d]
// order.
#pragma once

#include <cstdint>
#include <vector>

#include "cbrdf/brdf_table.h"

namespace cbrdf::internal {

struct SliceData {
  int nh = kThetaHBins, nd = 0, np = kPhiDBins;
  int theta_d_begin = 0;
  // The physical value of a stored value is value * unit. extract_slice gives unit 1; the fitter
  // works on a copy normalized by a power of two (normalize_slice).
  double unit = 1.0;
  std::vector<double> value;           // value in units of `unit`; 0 where not measured
  std::vector<std::uint8_t> measured;  // 1 where measured
  // The measured bins as a compact list, for the least-squares passes.
  std::vector<std::uint8_t> mi, mj;
  std::vector<std::uint16_t> mk;
  std::vector<double> mv;
  std::vector<double> mw;  // per measured bin: the loss's weight (1, or cos theta_i cos theta_o)
  // Measured bins of row (i, j) are mi/mj/mk/mv[row_begin[i * nd + j] .. row_begin[i * nd + j +
  // 1]).
  std::vector<std::uint32_t> row_begin;

  std::size_t at(int i, int j, int k) const {
    return (std::size_t(i) * std::size_t(nd) + std::size_t(j)) * std::size_t(np) + std::size_t(k);
  }
  std::size_t size() const { return value.size(); }
  std::size_t measured_count() const { return mv.size(); }
};

// cosine_weights: fill mw with cos(theta_i) cos(theta_o) at each bin's grid directions (else 1).
SliceData extract_slice(const BrdfTable& table, int channel, int theta_d_begin, int theta_d_end,
                        bool cosine_weights = false);

// Divides the values by 2^e, e the multiple of 3 that brings the largest measured value into
// [1, 8), and multiplies `unit` by 2^e: exact (no rounding) for finite values, so the fit, whose
// every step (sums, products, square and cube roots) commutes with such a power of two, gives the
// same result at any overall scale of the table, and never sees an intermediate square or sum
// overflow or underflow (which would leave the factorization stuck at its sweep cap).
void normalize_slice(SliceData* s);

}  // namespace cbrdf::internal
