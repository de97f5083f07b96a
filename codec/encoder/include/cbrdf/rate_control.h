// SPDX-License-Identifier: MIT
// Rate-distortion control: the encoder searches slices, components and bits for the best setting
// that meets a target, measured as the tone-mapped sphere PSNR of the decoded file against the
// input (metrics.h, sphere_psnr).
#pragma once

#include <cstdint>
#include <vector>

#include "cbrdf/encoder.h"
#include "cbrdf/export.h"

namespace cbrdf {

struct RateTarget {
  double max_bytes = 0;    // > 0: the highest PSNR within this many bytes
  double min_psnr = 0;     // > 0: the fewest bytes reaching this tone-mapped PSNR (dB)
  int max_components = 4;  // mixtures searched: 1 (the paper's model only) to this many components
  std::vector<int> slice_counts = {3, 6, 9, 15, 18, 30};  // uniform slice counts searched
};

struct RateCandidate {
  int slices = 0, bits = 0, components = 1;
  double bytes = 0, psnr_tonemapped = 0, psnr_linear = 0;
  double max_error = 0;  // the residual layer's bound (encode_to_target_ladder); 0: none
};

struct RateResult {
  EncodeResult encoded;  // the chosen file
  RateCandidate chosen;
  std::vector<RateCandidate> tried;  // every setting measured, in search order
  bool met = false;                  // false: no setting met the target; the closest is chosen
  // The search's work: (slice count, component count) models fitted, and HALS sweeps spent on
  // their mixtures (each component count continues the one before: FitLadder).
  int fits = 0;
  long long hals_sweeps = 0;
};

// Searches slices in target.slice_counts, components 1..max_components (each a fixed count per
// slice and channel) and bits 6..16 with the other settings of `base`.
// The search relies on bytes growing with slices, components and bits, and on PSNR growing with
// bits: per slice count the components are fitted in turn, each continuing the fit of the count
// before (FitLadder); per fitted model the bits are bisected (the most bits within the budget,
// or the fewest reaching the PSNR; 16 bits alone when even they miss it); larger component and
// slice counts are not fitted once their least possible bytes cannot beat the setting chosen
// (over the budget, or no fewer bytes than a setting reaching the PSNR). When no setting reaches
// the PSNR, the closest row is also measured at fewer bits while its PSNR stays saturated (within
// 0.05 dB of the best), since the last bits can cost a hair of PSNR there.
// Exactly one of max_bytes, min_psnr must be > 0 (kInvalidArgument otherwise).
CBRDF_EXPORT Expected<RateResult> encode_to_target(const BrdfTable& table,
                                                   const EncoderSettings& base,
                                                   const RateTarget& target);

// The whole ladder (residual_rate.cc): encode_to_target, then, when the model alone misses the
// PSNR (or a budget leaves room beyond it), the chosen model plus the residual layer with its
// bound E bisected in log scale over 1e-5..1: the largest E reaching the PSNR, or the smallest
// whose file fits the budget (kept only when it beats the model alone). chosen.max_error > 0
// names the layer chosen.
CBRDF_EXPORT Expected<RateResult> encode_to_target_ladder(const BrdfTable& table,
                                                          const EncoderSettings& base,
                                                          const RateTarget& target);

}  // namespace cbrdf
