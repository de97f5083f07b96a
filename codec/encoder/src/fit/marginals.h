// SPDX-License-Identifier: MIT
// Marginal masses of a slice, naive (missing bins as 0) or imputed (missing bins as the model's).
#pragma once

#include <vector>

#include "density/grid_copula.h"
#include "fit/slice_data.h"

namespace cbrdf::internal {

struct Marginals {
  std::vector<double> pdf_h, pdf_d, pdf_p;  // masses over theta_h, theta_d, phi_d; each sums to 1
  std::vector<double> cdf_h, cdf_d, cdf_p;  // midpoint CDFs
  double total = 0;                         // sum of the measured values
};

// The paper's estimate: sums over measured bins, as if missing bins were 0. total = measured sum.
Marginals naive_marginals(const SliceData& s);

// Re-estimates the marginals as if every missing bin held the model's value K c(U) pdf_h pdf_d
// pdf_p, by raking: each axis's bin total is its measured sum divided by the fraction of that bin's
// model mass that is measured, axis after axis, until no mass moves by more than `tolerance`
// (relative to the axis's largest mass) or `max_rounds` rounds. Returns rounds used.
int impute_marginals(const SliceData& s, GridCopula& copula, double theta, int max_rounds,
                     double tolerance, Marginals* m);

// Prepares `copula` at theta over m's CDFs.
void prepare(GridCopula& copula, double theta, const Marginals& m);

}  // namespace cbrdf::internal
