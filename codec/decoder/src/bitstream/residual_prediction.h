// SPDX-License-Identifier: MIT
// RESD's predicted codes (spec 4.6, "Predicted codes", predictor 3, version 1.3): before range
// coding, each measured bin's code is predicted from three codes coded before it, the same bin of
// the previous theta_h slab (U), of the previous channel (X) and of the previous channel's
// previous slab (XU), with coefficients per (channel, level) stored in the chunk; the stream
// codes what the prediction misses.
//
// Why: at fine bounds the codes of mode 3's interpolation are far from noise across slabs and
// channels: a code correlates with the previous slab's and the previous channel's at over 0.9,
// and the range coder's contexts know that a code is large but not its value. A fitted mix of
// both beats either alone (docs/benchmarks.md has the bytes).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "cbrdf/model.h"
#include "cbrdf/status.h"

namespace cbrdf {
class ByteReader;
}  // namespace cbrdf

namespace cbrdf::internal {

// A neighbour whose row step differs from the bin's by more than 2^8 is left out (contributes 0).
inline constexpr int kPredictionShiftLimit = 8;

// Coefficients in 1/256: per channel c and group g (the bin's level in modes 3 and 4, else 0),
// {a, b, g} for U, X and XU. Channel R has no channel before: its b and g are 0 and not stored.
struct CodePrediction {
  int groups = 1;                                 // levels + 1 in modes 3 and 4, else 1
  std::vector<std::array<std::int16_t, 3>> coef;  // kChannels x groups, channel-major

  std::array<std::int16_t, 3>& at(int c, int g) { return coef[std::size_t(c * groups + g)]; }
  const std::array<std::int16_t, 3>& at(int c, int g) const {
    return coef[std::size_t(c * groups + g)];
  }
  bool any() const;
};

// The groups of a residual: levels + 1 in modes 3 and 4, 1 in modes 0 and 2.
int prediction_groups(const Residual& residual);

// The shift of a row's step (0 without row shifts) and the group of every (theta_d, phi_d)
// position (the level in modes 3 and 4, else 0), as the reader and the writer's fit see them.
int row_shift_of(const Residual& residual, std::size_t row);
std::vector<std::uint8_t> group_table(const Residual& residual);

// The coefficients as stored: for c = R, G, B, for g = 0 .. groups - 1: a (R), or a, b, g
// (G and B), each an i16.
Status read_prediction(ByteReader& r, int groups, CodePrediction* out);

// q = r + P in place, slab by slab (decoder). kCorrupt when a code leaves -2^28..2^28; `at`
// (the stream's payload offset) is for the message.
Status unpredict_codes(std::int32_t* q, const NotMeasured& mask, const Residual& residual,
                       const CodePrediction& p, std::uint64_t at);

}  // namespace cbrdf::internal
