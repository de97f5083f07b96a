// SPDX-License-Identifier: MIT
// RESD's range-coded codes (spec 4.6, "Range-coded codes", version 1.3): the measured bins' codes
// through the adaptive binary range coder of 4.9 with contexts from codes coded before them: the
// same bin of the previous theta_h slab (and its phi_d neighbours, and the slab before) and of the
// previous channel, and the bin's level in mode 3's interpolation. Smaller than zigzag varints
// through zstd, most at coarse bounds (docs/benchmarks.md); the writer keeps the varints where
// they win.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "cbrdf/model.h"
#include "cbrdf/status.h"

namespace cbrdf::internal {

// The measured phi_d bins of the row whose first bin is mask bit b0, in increasing order: all of
// them for most rows (a static list of 0..179), else those written to `list`. Empty: none is
// measured. The codes' coder and the prediction of predictor 3 (residual_prediction.h) visit these.
std::span<const std::uint8_t> measured_bins(const NotMeasured& mask, std::size_t b0,
                                            std::array<std::uint8_t, kPhiDBins>& list);

// Decodes exactly `in` into q (kMaskBits, zero-filled by the caller; not-measured bins stay 0).
// `at` is the stream's payload offset, for messages. kCorrupt: a code beyond +-2^28, or bytes
// left unread; kTruncated: the stream ends before the last code.
Status decode_residual_codes(std::span<const std::uint8_t> in, std::uint64_t at,
                             const NotMeasured& mask, std::int32_t* q);

}  // namespace cbrdf::internal
