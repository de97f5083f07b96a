// SPDX-License-Identifier: MIT
// The fitting loss (FitLoss) at one measured bin: what the single-copula and the mixture fits
// minimize, with the derivative their Jacobians need.
#pragma once

#include <cmath>
#include <cstddef>

#include "cbrdf/fit.h"
#include "fit/slice_data.h"

namespace cbrdf::internal {

struct LossResidual {
  double r;      // the residual
  double dr_dm;  // its derivative in the model value
};

// The residual at measured bin q of s for a model value in units of the slice's mean measured
// value vbar (inv_vbar = 1 / vbar, physical_vbar = vbar * s.unit).
inline LossResidual loss_residual(FitLoss loss, const SliceData& s, std::size_t q, double model,
                                  double inv_vbar, double physical_vbar) {
  if (loss == FitLoss::kLog) {
    // Physical units: the stored values times the slice's unit.
    return {std::log1p(s.mv[q] * s.unit) - std::log1p(model * physical_vbar),
            -physical_vbar / (1.0 + model * physical_vbar)};
  }
  const double w = loss == FitLoss::kCosine ? std::sqrt(s.mw[q]) : 1.0;
  return {w * (s.mv[q] * inv_vbar - model), -w};
}

}  // namespace cbrdf::internal
