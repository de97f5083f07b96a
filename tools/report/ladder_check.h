// SPDX-License-Identifier: MIT
// The ladder's comparisons (issue 18's targets): bytes each method needs for a PSNR, read off its
// curve by interpolation in log bytes, and the ratios of the baselines to cbrdf.
#pragma once

#include <string>
#include <vector>

#include "report/ladder.h"

namespace cbrdf::report {

struct CurvePoint {
  double bytes = 0, psnr = 0;
};

// The points of a material's methods (any of `methods`) that no other of them beats in both
// bytes and tone-mapped PSNR, by increasing PSNR (and so increasing bytes).
std::vector<CurvePoint> ladder_curve(const LadderMaterial& m,
                                     const std::vector<std::string>& methods);

// Bytes to reach `psnr` on a curve: log-linear interpolation between the two points around it;
// the first point's bytes when psnr is below the curve (the fewest bytes measured); NaN above it.
double bytes_at(const std::vector<CurvePoint>& curve, double psnr);

// The methods making up cbrdf's curve (base, residual, lossless).
const std::vector<std::string>& cbrdf_methods();

struct LadderTarget {
  double psnr = 0;
  int materials = 0;             // materials where cbrdf reaches psnr (and ZFP was measured)
  int zfp_short = 0;             // of those, where ZFP's finest point is below psnr: its largest
                                 // file stands in, so the ZFP means and ratios are lower bounds
  double cbrdf_bytes = 0;        // mean over those materials
  double zfp_bytes = 0;          // mean; NaN without ZFP points
  double float16_bytes = 0;      // mean; NaN when float16 does not reach psnr on some material
  double zfp_ratio_min = 0;      // smallest per-material ZFP / cbrdf
  double float16_ratio_min = 0;  // smallest per-material float16 / cbrdf
};

// Targets 45, 50, ..., 80 dB tone-mapped.
std::vector<LadderTarget> ladder_targets(const std::vector<LadderMaterial>& ladders);

struct LosslessCheck {
  std::string material;
  double cbrdf = 0, xz = 0, zstd = 0;  // 0 when not measured
};
std::vector<LosslessCheck> lossless_checks(const std::vector<LadderMaterial>& ladders);

// The targets in a few lines: the ratios at 45-80 dB against 4x, the mean and largest
// bytes at 60 dB against 100 KB, lossless against xz on every material.
std::string ladder_check_text(const std::vector<LadderMaterial>& ladders);
// Its last two lines alone (empty when nothing reaches 60 dB, or without xz points).
std::string ladder_60db_text(const std::vector<LadderMaterial>& ladders);
std::string ladder_lossless_text(const std::vector<LadderMaterial>& ladders);

}  // namespace cbrdf::report
