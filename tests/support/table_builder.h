// SPDX-License-Identifier: MIT
// Synthetic MERL tables for the fitting tests, filled from a function of the bin indices.
#pragma once

#include <cstddef>

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

}  // namespace cbrdf::testing
