// SPDX-License-Identifier: MIT
// `cbrdf report --ladder` (issue 18): one material's bytes against tone-mapped and linear sphere
// PSNR from a few KB to lossless, for cbrdf (base model alone, base + residual layer, lossless)
// and the baselines (ZFP on log1p values, float16+zstd, zstd and xz of the .binary), each point
// with its encode and decode time.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "cbrdf/brdf_table.h"
#include "cbrdf/progress.h"
#include "cbrdf/status.h"

namespace cbrdf::report {

// Method names of ladder points.
inline constexpr const char* kLadderBase = "cbrdf base";
inline constexpr const char* kLadderResidual = "cbrdf residual";
inline constexpr const char* kLadderLossless = "cbrdf lossless";
inline constexpr const char* kLadderZfp = "zfp log1p";
inline constexpr const char* kLadderFloat16 = "float16+zstd";
inline constexpr const char* kLadderZstd = "zstd";
inline constexpr const char* kLadderXz = "xz";
// On a noisy table (noise.h): base + the residual --target-psnr writes at the noise floor (the
// smoothed residual at the floor's bound).
inline constexpr const char* kLadderNoiseFloor = "cbrdf noise floor";

struct LadderSettings {
  bool enabled = false;
  // Base model alone: every components x bits (frank, 6 uniform slices).
  std::vector<int> base_components = {1, 2, 4};
  std::vector<int> base_bits = {8, 12};
  // Base + residual (residual_base_components, residual_base_bits): bounds E of the finest rows
  // (spec 4.6, knee 1e-4 stored units). With row steps and mode 4 on the 20 shared materials,
  // 0.01 reads 49-63 dB tone-mapped, 1e-3 63-76, 3e-4 72-86 and 1e-4 78-93; 5e-5 takes the ones
  // that 1e-4 leaves below 80 dB past it, where the curve would otherwise run on to the lossless
  // file (about 9 MB), which closes it.
  std::vector<double> max_errors = {0.1, 0.03, 0.01, 3e-3, 1e-3, 3e-4, 1e-4, 5e-5};
  int residual_base_bits = 10;
  int residual_base_components = 1;  // measured: 4 components under the residual lost at 60 dB
  // Steps by the rows' visibility (ResidualSettings::row_steps, as --target-psnr encodes); E is
  // then the finest row's bound.
  bool residual_row_steps = true;
  // Codes correcting an interpolation of coarser bins (RESD mode 3, target_residual_settings).
  bool residual_interpolated = true;
  std::vector<double> zfp_tolerances = {0.5,  0.2,  0.08, 0.03, 0.012, 0.005,
                                        2e-3, 5e-4, 1e-4, 2e-5, 5e-6};
  bool float16 = true;
  bool lossless = true;     // cbrdf --lossless
  bool compressors = true;  // zstd and xz of the .binary
  int zstd_level = 19;
  std::uint32_t xz_preset = 9;
  int threads = 0;  // fitting threads (0: the thread limit)
  int sphere_size = 256;
  // The ladder's progress, 0 to 1 over the whole ladder, from its residual encodes and between
  // its points; returning false cancels (kCancelled). Empty: none.
  ProgressCallback progress;
};

struct LadderPoint {
  std::string method;   // one of the names above
  std::string setting;  // "k2 b12", "E 0.01", "tol 0.03", "level 19", ...
  double bytes = 0;
  double psnr_tonemapped = 0, psnr_linear = 0;  // kPsnrCapDb when exact
  double encode_s = 0, decode_s = 0;
  bool exact = false;  // decoded bit for bit (verified)
  // Against the noise-free truth (`cbrdf report --truth DIR`); NaN without one. Exact points: the
  // input's own PSNR against the truth.
  double psnr_truth_tonemapped = NAN;
};

struct LadderMaterial {
  std::string name;
  std::vector<LadderPoint> points;  // in the order of the methods above, settings as given
  // The input's noise estimate (noise.h): largest channel sigma and the PSNR ceiling it implies
  // (kPsnrCapDb for a smooth table).
  double noise_sigma = 0;
  double noise_ceiling_tonemapped = 0;
};

// Measures every point on `table` (as read from a MERL file; its serialize_merl bytes are what
// zstd and xz compress). Each point's decode is checked: lossless points must be bit-exact
// (kInternal otherwise).
// With `truth` (the noise-free table the input was measured from), every point is also measured
// against it.
Expected<LadderMaterial> measure_ladder(const std::string& name, const BrdfTable& table,
                                        const LadderSettings& st, const BrdfTable* truth = nullptr);

}  // namespace cbrdf::report
