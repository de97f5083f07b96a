// SPDX-License-Identifier: MIT
// Fitting a slice as a mixture of K copula components (beyond the paper; container version 1.1).
//
// Two stages. (1) The marginals of all components: a nonnegative rank-K factorization of the slice
// (theta_h x theta_d x phi_d) by hierarchical alternating least squares (HALS) with extrapolation
// between sweeps, started from the (K-1)-component fit plus one component built from the positive
// residual. Not-measured bins are handled by expectation-maximization: before each sweep they are
// filled with the current model's values, so they neither count as zeros nor pull the fit (the
// mixture's version of the imputed marginals). (2) The copula parameter and weight of every
// component, jointly, by Ceres on the fitting loss over measured bins, with the weights as
// logarithms so that they stay positive and the marginals fixed. The result never has a higher
// objective than the factorization alone (independence is inside every fitted family's range and
// is where stage 2 starts).
#pragma once

#include <vector>

#include "cbrdf/fit.h"
#include "cbrdf/model.h"
#include "fit/slice_data.h"

namespace cbrdf::internal {

inline constexpr int kMaxSweeps = 400;  // HALS sweeps per added component, at most

struct MixtureFit {
  ChannelSlice cs;                     // the components, largest K first
  double objective = 0;                // as ParameterFit::objective (mean loss per measured bin)
  double objective_factorization = 0;  // the same after stage 1 (all copulas at independence)
  int sweeps = 0;                      // HALS sweeps
  int unconverged = 0;  // factorizations stopped at the sweep cap (kMaxSweeps) before converging
  int solver_iterations = 0;  // Ceres iterations of stage 2
};

// Fits `components` (>= 2) components starting from `start` (a fit of this slice with fewer
// components, e.g. the paper's single component). Components that vanish during the
// factorization are dropped, so the result may hold fewer. Deterministic.
// Each added component costs at most kMaxSweeps HALS sweeps. Scales are in units of s.unit
// (fit/slice_data.h): with the slice normalized, the result does not depend on the table's
// overall scale.
// Without fit_copulas stage 2 is left out: every copula stays at independence and the weights
// are the factorization's (a nonnegative rank-K factorization of the slice; objective =
// objective_factorization). FitSettings::mixture_copulas says what that costs and saves.
MixtureFit fit_mixture(const SliceData& s, const ChannelSlice& start, int components,
                       CopulaFamily family, FitLoss loss, bool fit_copulas = true);

// The factorization (stage 1) where a fit_mixture_continued call left it: the unnormalized factors
// and the sweeps spent so far. Empty (rank 0, started false) before the first call.
struct MixtureState {
  std::vector<std::vector<double>> pdf_h, pdf_d, pdf_p;
  bool started = false;
  bool exhausted = false;  // nothing positive was left to explain: more components add nothing
  int sweeps = 0, unconverged = 0;
};

// fit_mixture with the factorization continued from `state` (the one a call with fewer
// components on the same slice and start left) instead of restarted from `start`: called with
// components = 2, 3, ... in turn, each result equals fit_mixture's at that count bit for bit (the
// factorization adds components one at a time either way), and each call costs only the sweeps
// of the components it adds and its own stage 2 (if fit_copulas). Counts must not decrease
// between calls.
MixtureFit fit_mixture_continued(const SliceData& s, const ChannelSlice& start, int components,
                                 CopulaFamily family, FitLoss loss, MixtureState* state,
                                 bool fit_copulas = true);

}  // namespace cbrdf::internal
