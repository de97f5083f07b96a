// SPDX-License-Identifier: MIT
// The measurements behind `cbrdf report`: per material, the codec at every sweep setting and the
// baselines, each as one Row; plus what the plots and images need.
#pragma once

#include <atomic>
#include <limits>
#include <string>
#include <vector>

#include "cbrdf/analytic_fit.h"
#include "cbrdf/image.h"
#include "cbrdf/status.h"
#include "report/ladder.h"
#include "report/sweep.h"

namespace cbrdf::report {

struct Material {
  std::string name;
  std::string path;  // MERL .binary; empty for a built-in sample
  bool builtin = false;
};

struct Settings {
  Sweep sweep;
  Baselines baselines;
  int lossless_zstd_level = 19;
  std::uint32_t xz_preset = 6;  // preset 9 is slower and no smaller on MERL files
  int float16_zstd_level = 19;
  int analytic_bins = 20000;
  AnalyticLoss analytic_loss = AnalyticLoss::kCosineWeighted;
  int sphere_size = 256;
  int jobs = 1;
  bool progress = true;  // a progress bar on stderr
  // Set (not null) and then true: the running encodes stop through their progress callbacks and
  // measure_all fails with kCancelled. For Ctrl-C.
  const std::atomic<bool>* cancel = nullptr;
  LadderSettings ladder;  // `--ladder`: measured when ladder.enabled
  // `--truth DIR`: the noise-free tables of noisy inputs, DIR/NAME.binary for an input
  // NAME.binary or NAME-noisy.binary; the ladder is also measured against them.
  std::string truth_dir;
  // Time renders of the figure-4 layout (render_times.h) from the primary and paper settings'
  // models and from the measured table, at sphere_size / 256 times its 1320x240 pixels.
  bool render_times = true;
  // `--format-version`: the container codings measured, each "auto", "1.2" or "1.3". The first is
  // the rows' own; each further one is measured beside it at every copula setting (same fit) into
  // Row::codings, for the report's side-by-side frontier. "1.2" is written with full metadata, as
  // every encoder before 1.3 wrote it.
  std::vector<std::string> codings = {"auto"};
};

// One copula setting written in one coding (Settings::codings).
struct CodingResult {
  std::string coding;  // "auto", "1.2" or "1.3"
  double bytes = 0;
  double psnr_linear = 0, psnr_tonemapped = 0;
  double encode_s = 0;  // fit + quantize + container, as Row::encode_s
};

// Row kinds.
inline constexpr const char* kKindCopula = "copula";
inline constexpr const char* kKindLossless = "lossless";
inline constexpr const char* kKindNearLossless = "near-lossless";
inline constexpr const char* kKindAnalytic = "analytic";

struct Row {
  std::string material;
  std::string model;         // frank, ..., separable, auto, zstd-19, xz-6, float16+zstd, ward, ...
  std::string kind;          // one of the kinds above
  int slices = 0, bits = 0;  // copula rows
  int components = 1;        // copula rows: 1 to kMaxComponents, or kAutoComponents
  double max_error = 0;      // copula rows: the residual layer's bound (CodecSetting), 0: none
  bool in_sweep = false;     // a copula row of the sweep (not only a baseline)
  bool primary = false;      // the sweep's primary setting
  bool paper = false;        // the paper's setting (paper_setting()), measured in every report
  double input_bytes = 0;    // the .binary
  double bytes = 0;          // container, compressed file, or 8 bytes per analytic parameter
  double rel_rmse = 0, log_rmse = 0, cos_rmse = 0;  // metrics.h, over the measured bins
  double psnr_linear = 0, psnr_tonemapped = 0;      // sphere images, against the input
  double encode_s = 0;  // fit + quantize + container (or compression, or the analytic fit)
  double decode_s = 0;  // bytes (or parameters) to a full table
  double eval_ns = 0;   // one RGB evaluation at a random direction pair
  std::string detail;   // e.g. the fitted analytic parameters
  // The figure-4 layout rendered with this model on one thread (render_times.h): the primary and
  // paper settings' models and the lossless rows (the measured table, nearest-bin); NaN otherwise.
  double render_s = std::numeric_limits<double>::quiet_NaN();
  // Copula rows when Settings::codings holds more than one: every coding's result, in that order
  // (the first repeats this row's own); empty otherwise.
  std::vector<CodingResult> codings;

  std::string label() const;  // "frank s6 b10", "frank s6 b10 k2", "frank s6 b10 E0.03", "ward"
  double ratio() const { return bytes > 0 ? input_bytes / bytes : 0.0; }
};

// BRDF (mean of the channels) in the plane of incidence, theta_o signed (negative on the side
// of the mirror direction), as the paper's Figure 3.
struct PolarCurve {
  std::string model;  // "measured" or a row's label
  double theta_i_deg = 0;
  std::vector<double> theta_o_deg, value;
};
inline constexpr double kPolarThetaI[] = {0.0, 45.0, 75.0};

struct MaterialResult {
  std::string name;
  std::vector<Row> rows;
  std::vector<PolarCurve> polar;
  // Sphere renders lit at 45 degrees, tone-mapped with the reference's exposure, and their
  // false-colour difference (viridis, the same scale for every material): paper's Figure 4.
  Image reference, decoded, difference;
  std::string decoded_label;
  LadderMaterial ladder;  // empty without --ladder
  // The figure-4 layout rendered from the measured table (render_times.h), nearest-bin and
  // trilinear, and the lookups' eval costs; NaN without Settings::render_times.
  double render_nearest_s = std::numeric_limits<double>::quiet_NaN();
  double render_trilinear_s = std::numeric_limits<double>::quiet_NaN();
  double nearest_eval_ns = std::numeric_limits<double>::quiet_NaN();
  double trilinear_eval_ns = std::numeric_limits<double>::quiet_NaN();
  int render_width = 0, render_height = 0;
};
inline constexpr double kImageLightDeg = 45.0;
inline constexpr double kDifferenceScale = 0.1;  // display units shown as full yellow

// Measures every material (`jobs` at a time). The first error stops the report.
Expected<std::vector<MaterialResult>> measure_all(const std::vector<Material>& materials,
                                                  const Settings& st);

}  // namespace cbrdf::report
