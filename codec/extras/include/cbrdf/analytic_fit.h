// SPDX-License-Identifier: MIT
/// @file
/// Fitting analytic BRDFs (analytic.h) to a measured table, after Ngan, Durand and Matusik 2005
/// ("Experimental analysis of BRDF models"): the compact baselines the copula codec is compared
/// with, and a quick analytic approximation of a measured material.
/// Part of the extras library (libcbrdf_extras).
///
/// What is fitted: a deterministic subsample of the bins measured in all three channels whose grid
/// direction pair (coords.h bin angles, phi_h = 0, as tabulate() uses) has theta_i and theta_o at
/// most max_angle_deg (Ngan et al. drop the grazing configurations above 80 degrees, where
/// measurements are least reliable). Every lobe's colour and shape are fitted jointly with Ceres
/// (numeric derivatives), started from a scan: for each specular lobe in turn, a log-spaced grid of
/// shapes, each with the colours that are then optimal (non-negative weighted least squares per
/// channel, exact because every lobe is affine in its colour).
#pragma once

#include <cstdint>
#include <vector>

#include "cbrdf/analytic.h"
#include "cbrdf/brdf_table.h"
#include "cbrdf/status.h"

namespace cbrdf {

/// What fit_analytic minimizes.
enum class AnalyticLoss : std::uint8_t {
  /// sum w (f - m)^2 / sum w with w = cos(theta_i) cos(theta_o) times the bin's measure, over the
  /// fitted bins and channels: the square of cbrdf/metrics.h's cos_rmse restricted to those
  /// bins. Ngan et al. fit a cosine-weighted L2 like this one; it favours the bright part of the
  /// lobe.
  kCosineWeighted = 0,
  /// mean (log(1 + f) - log(1 + m))^2: the square of cbrdf/metrics.h's log_rmse on those bins.
  /// Weighs the dim tails more, at the cost of the highlight's peak.
  kLog = 1,
};

/// At most this many lobes: the scan's non-negative least squares enumerates subsets of them.
inline constexpr int kMaxFitLobes = 4;

/// What fit_analytic fits, and how.
struct AnalyticFitSettings {
  /// The model: lobe kinds in order (their parameters are fitted). E.g. Lambertian + Ward.
  std::vector<LobeKind> lobes = {LobeKind::kLambertian, LobeKind::kGgx};
  int sample_bins = 20000;  ///< bins fitted; 0 (or more than are eligible) fits every eligible bin
  std::uint64_t seed = 1;   ///< which bins: the same seed always draws the same ones
  double max_angle_deg = 80.0;  ///< bins with theta_i or theta_o above this are not fitted
  AnalyticLoss loss = AnalyticLoss::kCosineWeighted;  ///< the loss minimized
  int max_iterations = 100;                           ///< Ceres iterations
  /// Ceres stops when an iteration changes the loss by less than this fraction. The scan's start
  /// is usually close: on measured materials tighter tolerances cost several times the time for
  /// changes in the fourth digit of the loss.
  double function_tolerance = 1e-7;
  int threads = 1;  ///< residual blocks evaluated in parallel; the result does not change
};

/// How a fit went.
struct AnalyticFitReport {
  int bins = 0;             ///< bins fitted (each with three channels)
  double start_cost = 0.0;  ///< the loss at the scan's best start
  double final_cost = 0.0;  ///< the loss at the returned parameters
  int iterations = 0;       ///< Ceres iterations
};

/// Fits the lobes' parameters to the table. Errors (kInvalidArgument): no lobes or more than
/// kMaxFitLobes, sample_bins < 0, max_angle_deg outside (0, 90], max_iterations < 1, threads < 1,
/// function_tolerance not in (0, 1), or no eligible bin (nothing measured below max_angle_deg).
Expected<AnalyticBrdf> fit_analytic(const BrdfTable& table, const AnalyticFitSettings& settings,
                                    AnalyticFitReport* report = nullptr);

/// The BRDF at every bin's grid direction pair where the reference is measured (per channel), and
/// the reference's stored value where it is not: a table comparable bin for bin with the reference.
/// Errors: the BRDF does not validate (cbrdf/analytic.h), or yields a non-finite value (kNumeric).
Expected<BrdfTable> tabulate_like(const AnalyticBrdf& brdf, const BrdfTable& reference);

}  // namespace cbrdf
