// SPDX-License-Identifier: MIT
/// @file
/// The measurement noise of a table, estimated from the table alone, and what it implies: the
/// sphere PSNR beyond which coding the table reproduces its noise, and a denoised target for the
/// residual layer so that the ladder spends bytes on signal.
///
/// The estimate: in the log domain, where multiplicative (camera, light, calibration) noise of
/// relative size s is additive with standard deviation s, the fourth difference along phi_d,
/// d = (x[i-2] - 4 x[i-1] + 6 x[i] - 4 x[i+1] + x[i+2]) / sqrt(70), of five consecutive measured
/// positive bins. A BRDF is smooth along phi_d at 1-degree bins (the difference of a smooth signal
/// is near 0), while independent noise of deviation s gives d deviation s; the median of |d| over a
/// band, divided by 0.6745 (the median of |N(0,1)|), ignores the few sharp features (highlights,
/// the horizon).
#pragma once

#include <array>
#include <vector>

#include "cbrdf/brdf_table.h"

namespace cbrdf {

/// Bands of theta_d: the growth of noise towards grazing angles.
inline constexpr int kNoiseBands = 6;
/// theta_d bins per band (15).
inline constexpr int kNoiseBandDegrees = kThetaDBins / kNoiseBands;

/// Below this relative deviation in every channel a table counts as noise-free: the 20 neural
/// fits of MERL measurements estimate below 1e-8, 1% noise at about 0.01.
inline constexpr double kNoiseFreeSigma = 0.002;

/// What estimate_noise() found in a table.
struct NoiseEstimate {
  /// The relative noise per channel (R, G, B): the deviation of log(value), so 0.03 is 3%.
  std::array<double, 3> sigma{};
  /// The same per theta_d band (band b: theta_d bins 15 b to 15 b + 14), per channel; 0 where a
  /// band has too few bins to say.
  std::array<std::array<double, 3>, kNoiseBands> band_sigma{};
  /// The mean over channels of the last band's sigma over the first band's: 1 for noise that does
  /// not depend on the angle, 4 when it is 4 times larger near grazing.
  double grazing_growth = 1.0;
  /// The tone-mapped sphere PSNR (metrics.h) of the table against itself with another draw of
  /// noise of the estimated size: about the PSNR of the table against the noise-free truth, so
  /// beyond it a coder reproduces noise, not signal. kPsnrCapDb when noise-free. NaN when not
  /// measurable: noise so large (many decades per bin) that the other draw's renders leave the
  /// range of a float image.
  double psnr_ceiling_tonemapped = 0.0;
  /// The same in linear sphere PSNR; NaN when not measurable, as above (the linear renders
  /// overflow first: values log-uniform over 1e-30..1e30 give a finite tone-mapped ceiling and
  /// NaN here).
  double psnr_ceiling_linear = 0.0;
  /// Five-bin runs the estimate used (per channel, summed).
  std::size_t samples = 0;
  /// Any channel above kNoiseFreeSigma.
  bool noisy() const;
  /// The largest channel sigma.
  double max_sigma() const;
};

/// How estimate_noise() works.
struct NoiseOptions {
  bool ceiling = true;  ///< false: skip the sphere renders (psnr_ceiling_* left 0)
  int threads = 0;      ///< sphere renders' threads (0: the library's limit)
};

/// Estimates the relative measurement noise of `table` (see the file comment) and, unless
/// options.ceiling is false, the PSNR ceiling it implies.
NoiseEstimate estimate_noise(const BrdfTable& table, const NoiseOptions& options = {});

/// The table the residual layer codes when the input is noisy: `base` (the model as decoded) times
/// the ratio table / base smoothed over theta_d and phi_d (a Gaussian of `radius` bins, measured
/// bins only, on log1p(value / knee)); the model carries the sharp features, so the ratio is smooth
/// where the signal is and averaging it removes most of the noise. Not-measured bins are copied.
BrdfTable smooth_residual_target(const BrdfTable& table, const BrdfTable& base, double knee,
                                 double radius);

/// The rate control's residual on a noisy table (--target-psnr, --target-bytes, the report's
/// noise-floor point) is smooth_residual_target with this radius and the residual's knee.
/// Measured on the 20 materials of ../shared at 3% (tools/scripts/bench-noisy.py).
inline constexpr double kDenoiseRadius = 2.0;
/// The residual's bounds E are no smaller than this times the largest channel sigma (the noise
/// floor).
inline constexpr double kFloorPerSigma = 0.5;
/// smooth_residual_target(table, base, the residual's knee, kDenoiseRadius).
BrdfTable noise_floor_source(const BrdfTable& table, const BrdfTable& base);
/// The smallest residual bound E worth coding for a table of this noise: kFloorPerSigma times
/// estimate.max_sigma(), at most 16 (the largest bound a file holds).
double noise_floor_error(const NoiseEstimate& estimate);

}  // namespace cbrdf
