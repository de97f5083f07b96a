// SPDX-License-Identifier: MIT
// Synthetic MERL tables for the fitting tests, filled from a function of the bin indices.
#pragma once

#include <cmath>
#include <cstddef>
#include <random>

#include "cbrdf/brdf_table.h"
#include "cbrdf/coords.h"

namespace cbrdf::testing {

// A table filled by f(channel, theta_h bin, theta_d bin, phi_d bin) (physical values); bins
// below the horizon are marked not measured, as in real files, unless horizon_mask is false.
template <typename F>
BrdfTable make_table(F f, bool horizon_mask = true) {
  BrdfTable t;
  for (std::size_t idx = 0; idx < kBinsPerChannel; ++idx) {
    const BinIndex b = merl_bin(idx);
    if (horizon_mask && bin_below_horizon(b.theta_h, b.theta_d, b.phi_d)) {
      t.set_not_measured(idx);
      continue;
    }
    for (int c = 0; c < kChannels; ++c) t.set_physical(c, idx, f(c, b.theta_h, b.theta_d, b.phi_d));
  }
  return t;
}

// Values exp(U(log lo, log hi)) at every bin above the horizon (a valid table whose values span
// many decades); the others not measured.
inline BrdfTable log_uniform_table(double lo, double hi, unsigned seed) {
  BrdfTable t;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(std::log(lo), std::log(hi));
  for (int th = 0; th < kThetaHBins; ++th) {
    for (int td = 0; td < kThetaDBins; ++td) {
      for (int p = 0; p < kPhiDBins; ++p) {
        const std::size_t i = merl_index(th, td, p);
        if (bin_below_horizon(th, td, p)) {
          t.set_not_measured(i);
          continue;
        }
        for (int c = 0; c < kChannels; ++c) t.set_physical(c, i, std::exp(u(rng)));
      }
    }
  }
  return t;
}

}  // namespace cbrdf::testing
