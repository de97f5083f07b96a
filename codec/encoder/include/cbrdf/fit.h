// SPDX-License-Identifier: MIT
/// @file
/// Fitting the copula model to a measured table.
///
/// Per colour channel the table is cut into slices along theta_d. Each slice is normalized over its
/// bins (Eq. 14), its marginal masses over theta_h, theta_d and phi_d estimated (Eq. 17), and the
/// copula parameter fitted by least squares on Eq. 17 with Ceres, over measured bins only.
///
/// Conventions (see spec/container.md for the stored form):
/// - Marginals are probability masses per MERL bin (each axis sums to 1). theta_h is treated in
/// MERL
///   index space: the data are samples on that grid, so each bin's mass is just the normalized sum
///   of its samples, and the grid's square-root spacing spreads the sharp specular peak over more
///   bins than a uniform angle axis would, making the marginal less skewed.
/// - CDF values are taken at bin midpoints: U_i = sum_{k<i} f_k + f_i / 2. Midpoints keep u away
///   from exactly 0 and 1 (where copula densities are singular) and make the discrete model
///   integrate exactly to K at independence.
/// - Not-measured bins do not count as 0: the marginals are estimated as if they held the model's
///   own values (fill, re-estimate, repeat), because zeros skew every marginal near grazing angles.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "cbrdf/brdf_table.h"
#include "cbrdf/copula_family.h"
#include "cbrdf/model.h"
#include "cbrdf/slicing.h"
#include "cbrdf/status.h"

namespace cbrdf {

/// What the least-squares fit of each slice minimizes, over measured bins (v: measured, m: model).
/// Only the parameter and K are fitted (the marginals come from the data), so the choice moves the
/// mean sphere PSNR by hundredths of a dB (docs/benchmarks.md).
enum class FitLoss {
  kLinear,  ///< sum (v - m)^2: the paper's Eq. 17
  kCosine,  ///< sum cos(theta_i) cos(theta_o) (v - m)^2 at the bin's grid directions (Ngan et al.)
  kLog,     ///< sum (log(1 + v) - log(1 + m))^2, physical units: relative error, as images show it
};

/// How fit_model() fits a table (EncoderSettings::fit).
struct FitSettings {
  int slices = 6;  ///< uniform slices along theta_d, 1 to 90
  /// Explicit boundaries (overrides `slices`): 0 = b0 < ... < bn = 90.
  std::vector<int> slice_bounds;
  /** Boundaries chosen from the data (slicing.h) instead of uniform: `adaptive_slices` places
      `slices` slices; `auto_slices` also chooses the count (choose_slice_count). Measured on the 20
      real materials at 6 slices: -3.7 dB tone-mapped sphere PSNR against uniform (the metric's
      three lights only see theta_d 5, 22 and 37 degrees), +0.3 to +0.6 dB with lights from 20 to
      165 degrees; so they are options, not the default. */
  ///@{
  bool adaptive_slices = false;
  bool auto_slices = false;
  ///@}
  SlicingSettings slicing;                     ///< adaptive and auto slicing's settings
  CopulaFamily family = CopulaFamily::kFrank;  ///< the copula (unless auto_family)
  FitLoss loss = FitLoss::kLinear;             ///< what the copula parameter minimizes
  bool auto_family = false;        ///< fit every family per slice and channel, keep the best
  bool impute_missing = true;      ///< false: the paper's naive marginals (missing bins as 0)
  int impute_iterations = 30;      ///< cap on fill/re-estimate rounds per parameter update
  double impute_tolerance = 1e-7;  ///< stop when no mass changes by more than this (relative)
  /// After the first fit, impute again under the fitted copula and refit. Off by default: on the
  /// 20 real materials it changed tone-mapped sphere PSNR by at most 0.06 dB for twice the time.
  bool impute_with_copula = false;
  /** Components per slice and channel: 1 is the paper's model; more make each slice a mixture
      (fit/mixture.h; a version 1.1 file). With auto_components, `components` is the most per slice
      and channel, and each added component must bring the objective down to auto_component_gain
      times what it was. */
  ///@{
  int components = 1;
  bool auto_components = false;
  double auto_component_gain = 0.5;
  ///@}
  /// Mixtures: fit each component's copula parameter and the weights jointly (stage 2 of
  /// fit/mixture.h). false leaves every copula at independence with the factorization's weights,
  /// at about half the fit's cost. On 9 settings of 7 real materials (rate control's choices at
  /// 12 KB and 45 dB) that made files 5.5-7.2% smaller at the same bits, for a tone-mapped sphere
  /// PSNR from 0.52 dB lower to 0.03 dB higher (the copula fit minimizes the linear loss, not that
  /// metric): about even, so rate control searches mixtures this way, at half the time
  /// (RateTarget::mixture_copulas). One component always fits its copula.
  bool mixture_copulas = true;
  int threads = 1;  ///< slices and channels fitted in parallel; results identical
};

inline constexpr int kMaxComponents = 8;      ///< the most components per slice and channel
inline constexpr int kAutoMaxComponents = 4;  ///< the most `--components auto` tries

/// What the fit did, per slice and channel.
struct ChannelSliceFit {
  double objective = 0;  ///< S(theta) of Eq. 17 at the fitted parameter, per measured bin
  double objective_independence = 0;  ///< the same at the separable model (theta at independence)
  int solver_iterations = 0;          ///< Ceres iterations
  int hals_sweeps = 0;                ///< mixtures: sweeps of the factorization
  /// Mixtures: factorizations that stopped at the cap of 400 sweeps per component before their
  /// objective settled (the fit is still used; it is the best found within the cap).
  int hals_unconverged = 0;
  int impute_rounds = 0;  ///< fill/re-estimate rounds of the missing bins
  int measured_bins = 0;  ///< bins of the slice and channel with a measurement
};

/// The fit's diagnostics (fit_model's optional output).
struct FitReport {
  std::vector<std::array<ChannelSliceFit, kChannels>> slices;  ///< per slice, R, G, B
};

/** The values a table may hold where it is measured: in each channel the largest measured value is
    0 (the channel is all 0) or lies in [kMinPeakMeasuredValue, kMaxMeasuredValue]. Inside this
    range the decoded table equals the one of the same table scaled to ordinary values, scaled back
    (to about 1e-13 relative): the fit works on a power-of-two normalized copy and the stored K
    keeps 1e50 of headroom before any product of the evaluation overflows or turns subnormal. Beyond
    it K or the values rebuilt from it would overflow (1e300 times a material decoded 13,000 bins to
    the largest double) or lose their precision in subnormals. */
///@{
inline constexpr double kMaxMeasuredValue = 1e250;
inline constexpr double kMinPeakMeasuredValue = 1e-250;
///@}

/// Fits the model. Errors: invalid settings (kInvalidArgument); a channel whose largest measured
/// value is outside the supported range above (kNumeric, naming the channel and the value).
Expected<Model> fit_model(const BrdfTable& table, const FitSettings& settings,
                          FitReport* report = nullptr);

/// Fits of one table at one slicing with 1, 2, 3, ... components (fixed counts per slice and
/// channel), for searches over the component count (rate control): fit(k) equals fit_model with
/// `components = k` and `auto_components = false` bit for bit, but the one-component fit is done
/// once and each k continues the factorization that k - 1 left (fit/mixture.h: components are
/// added one at a time either way), so fitting 1..K costs about what fitting K alone does instead
/// of their sum. Models are kept: asking again for a count is free. Slicing (auto, adaptive) is
/// resolved once. The table must outlive the ladder.
class FitLadder {
 public:
  /// Settings are checked by the first fit(), which reports their errors as fit_model does.
  FitLadder(const BrdfTable& table, const FitSettings& settings);
  ~FitLadder();
  /** Move-only. */
  ///@{
  FitLadder(FitLadder&&) noexcept;
  FitLadder& operator=(FitLadder&&) noexcept;
  ///@}

  /// The model with `components` (1 to kMaxComponents) per slice and channel.
  Expected<Model> fit(int components, FitReport* report = nullptr);
  /// Component counts actually fitted so far (each one pass over the table's slices).
  int fits() const;
  /// HALS sweeps spent so far over all slices and channels (a sweep is never repeated).
  long long hals_sweeps() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

/// The slice boundaries the settings describe, validated.
Expected<std::vector<int>> slice_bounds(const FitSettings& settings);

}  // namespace cbrdf
