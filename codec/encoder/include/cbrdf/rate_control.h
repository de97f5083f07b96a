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
};

struct RateResult {
  EncodeResult encoded;  // the chosen file
  RateCandidate chosen;
  std::vector<RateCandidate> tried;  // every setting measured, in search order
  bool met = false;                  // false: no setting met the target; the closest is chosen
};

// Searches slices in target.slice_counts, components 1..max_components (each a fixed count per
// slice and channel) and bits 6..16 with the other settings of `base`.
// Exactly one of max_bytes, min_psnr must be > 0 (kInvalidArgument otherwise).
CBRDF_EXPORT Expected<RateResult> encode_to_target(const BrdfTable& table,
                                                   const EncoderSettings& base,
                                                   const RateTarget& target);

}  // namespace cbrdf
