// Least-squares fit of a slice's copula parameter and scale with Ceres (Eq. 17).
#pragma once

#include "fit/grid_copula.h"
#include "fit/marginals.h"
#include "fit/slice_data.h"

namespace cbrdf::fit {

struct ParameterFit {
  double theta = 0;
  double scale = 0;      // K minimizing sum over measured bins of (v - K c f1 f2 f3)^2
  double objective = 0;  // mean over measured bins of ((v - K c f1 f2 f3) / mean v)^2
  double objective_independence = 0;  // the same at independence (K optimal there)
  int iterations = 0;
};

// The best scale and objective at a fixed parameter (closed form in K).
ParameterFit evaluate_parameter(const SliceData& s, const Marginals& m, GridCopula& copula,
                                double theta);

// Fits theta in [copula.fit_lo(), copula.fit_hi()] and K jointly, started from the best of a
// coarse scan of theta. Deterministic.
ParameterFit fit_parameter(const SliceData& s, const Marginals& m, GridCopula& copula);

}  // namespace cbrdf::fit
