// SPDX-License-Identifier: MIT
/// @file
/// Rate-distortion control: the encoder searches slices, components and bits for the best setting
/// that meets a target, measured as the tone-mapped sphere PSNR of the decoded file against the
/// input (metrics.h, sphere_psnr).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cbrdf/encoder.h"

namespace cbrdf {

/// What encode_to_target() aims for: set max_bytes or min_psnr.
struct RateTarget {
  double max_bytes = 0;  ///< > 0: the highest PSNR within this many bytes
  double min_psnr = 0;   ///< > 0: the fewest bytes reaching this tone-mapped PSNR (dB)
  /// Mixtures searched: 1 (the paper's model only) to this many components.
  int max_components = 4;
  std::vector<int> slice_counts = {3, 6, 9, 15, 18, 30};  ///< uniform slice counts searched
  /// Mixtures are searched with their copulas at independence (FitSettings::mixture_copulas: about
  /// even in PSNR per byte on the real materials, at half the fit's time); true fits them.
  bool mixture_copulas = false;
};

/// One setting the search measured.
struct RateCandidate {
  /** The setting. */
  ///@{
  int slices = 0, bits = 0, components = 1;
  ///@}
  /** Its file size and sphere PSNR (dB). */
  ///@{
  double bytes = 0, psnr_tonemapped = 0, psnr_linear = 0;
  ///@}
  double max_error = 0;  ///< the residual layer's bound (encode_to_target_ladder); 0: none
};

/// What encode_to_target() chose, and what it tried.
struct RateResult {
  EncodeResult encoded;              ///< the chosen file
  RateCandidate chosen;              ///< the chosen setting
  std::vector<RateCandidate> tried;  ///< every setting measured (decoded, PSNR), in search order
  bool met = false;                  ///< false: no setting met the target; the closest is chosen
  /** The search's work: (slice count, component count) models fitted, and HALS sweeps spent on
      their mixtures (each component count continues the one before: FitLadder). */
  ///@{
  int fits = 0;
  long long hals_sweeps = 0;
  ///@}
  /// encode_to_target_ladder on a noisy table that stopped at its noise floor, or that chose the
  /// model alone because no residual layer can be written on the table: one line saying so
  /// (printed by `cbrdf encode`); empty otherwise.
  std::string note;
  /// The residual layer codes the input with its measurement noise smoothed out (a noisy table
  /// under encode_to_target_ladder): its bound holds against that, not against the input.
  bool residual_of_smoothed_input = false;
};

/// Searches slices in target.slice_counts, components 1..max_components (each a fixed count per
/// slice and channel) and bits 6..16 with the other settings of `base`.
/// The search relies on bytes growing with slices, components and bits, and on PSNR growing with
/// bits. It fits one component at each slice count in turn until a slice count does not beat the
/// smaller ones (PSNR against slices rises to a few slices, then is flat or falls), then adds one
/// component at a time to the slice counts still open, each continuing the fit of the count
/// before (FitLadder; mixtures with their copulas at independence unless target.mixture_copulas).
/// Candidates are measured with a SphereScorer (metrics.h): the same PSNR as decoding the file. Per
/// fitted model the bits are bisected: at a budget on bytes alone (encoding without decoding), and
/// only the most bits within it are measured; at a PSNR the fewest bits reaching it (16 bits alone
/// when even they miss it). A slice or component count is not fitted when it cannot win: its least
/// possible bytes (6 bits, measured, or forecast from the counts fitted with a 6% margin) are over
/// the budget or no fewer than a setting reaching the PSNR; or its PSNR, bounded by the row before
/// plus the largest gain that component brought at any slice count (else the gain of the component
/// before) plus 1 dB, cannot beat the best setting within the budget or reach a PSNR already met;
/// or the component before did not raise its row's PSNR. The forecasts, the gain bound and the end
/// of the slice search are heuristics, not proofs (they matched the full search of the previous
/// version on the real materials measured, and an exhaustive search on a small grid in
/// tests/encoder/rate_control_test.cc); they are what keeps a search within a few default encodes.
/// When no setting reaches the PSNR, the closest row is also measured at fewer bits while its PSNR
/// stays saturated (within 0.05 dB of the best), since the last bits can cost a hair of PSNR there.
/// Exactly one of max_bytes, min_psnr must be > 0 (kInvalidArgument otherwise).
Expected<RateResult> encode_to_target(const BrdfTable& table, const EncoderSettings& base,
                                      const RateTarget& target);

/// The whole ladder (residual_rate.cc): encode_to_target, then, when the model alone misses the
/// PSNR (or a budget leaves room beyond it), the chosen model plus the residual layer with its
/// bound E searched over 1e-5..1 by the secant on PSNR (or the residual's log bytes) against log E,
/// about 3 tries: the largest E reaching the PSNR (within 0.15 dB), or the smallest whose file
/// fits the budget (within 2% of it; kept only when it beats the model alone). When no model
/// reaches the PSNR, the residual goes on the one-component model at the settings' slice count and
/// --bits auto's bits (a third to a half of the bytes of one on the closest model on the real
/// materials); a PSNR more than any mixture adds (8 dB) above the best one-component row fits no
/// mixture. When even the smallest E misses the PSNR, the closest file is chosen. On a noisy table
/// no E is below its noise floor (noise_floor_error(): at most 16, which then also ends the range
/// searched). A bound the layer cannot hold on the table (more bins tens of e-folds from the model
/// than RESD stores exactly) is followed by one try at the largest, 16; when even that cannot be
/// written, the model alone is chosen with a note. So an unreachable target on any valid table
/// gives the closest file (met false), not an error. chosen.max_error > 0 names the layer.
Expected<RateResult> encode_to_target_ladder(const BrdfTable& table, const EncoderSettings& base,
                                             const RateTarget& target);

}  // namespace cbrdf
