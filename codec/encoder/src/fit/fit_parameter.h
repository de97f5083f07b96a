// SPDX-License-Identifier: MIT
// Least-squares fit of a slice's copula parameter and scale with Ceres (Eq. 17).
#pragma once

#include "cbrdf/fit.h"
#include "density/grid_copula.h"
#include "fit/marginals.h"
#include "fit/slice_data.h"

namespace cbrdf::internal {

struct ParameterFit {
  double theta = 0;
  double scale = 0;  // K, in units of the slice's SliceData::unit
  // Mean over measured bins of the loss: for kLinear ((v - K c pdf_h pdf_d pdf_p) / mean v)^2,
  // kCosine the same weighted by cos(theta_i) cos(theta_o), kLog (log(1 + v) - log(1 + K c pdf_h
  // pdf_d pdf_p))^2.
  double objective = 0;
  double objective_independence = 0;  // the same at independence (K optimal there)
  int iterations = 0;
};

// The objective at a fixed parameter, with K the (weighted) linear least-squares scale in closed
// form (for kLog a start for the joint fit, not its optimum).
ParameterFit evaluate_parameter(const SliceData& s, const Marginals& m, GridCopula& copula,
                                double theta, FitLoss loss = FitLoss::kLinear);

// Fits theta in [copula.search_lo(), copula.search_hi()] and K jointly, started from the best of a
// coarse scan of theta. Deterministic.
ParameterFit fit_parameter(const SliceData& s, const Marginals& m, GridCopula& copula,
                           FitLoss loss = FitLoss::kLinear);

}  // namespace cbrdf::internal
