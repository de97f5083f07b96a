// SPDX-License-Identifier: MIT
// BASE's marginal tables (spec 4.7): the predictors of a table's codes and the adaptive contexts
// of the stream, which the reader (base.cc) and the encoder's writer (base_writer.cc) share so
// that both predict every code alike.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "cbrdf/model.h"
#include "range_coder.h"

namespace cbrdf::base_marginals {

inline constexpr const char* kAxisNames[3] = {"theta_h", "theta_d", "phi_d"};

// Predictors of a table's codes (spec 4.7): from the bin before, by linear extrapolation, from the
// bin before plus the reference table's step, and the same step rescaled to this table's range.
inline constexpr int kPredictors = 4;
inline constexpr int kPredictPrevious = 0, kPredictLinear = 1, kPredictRefStep = 2,
                     kPredictRefScaled = 3;

// All adaptive state of the marginal stream.
struct MarginalContexts {
  std::array<internal::SIntContexts, 3> hi{}, span{};  // range deltas, per axis
  std::array<std::array<internal::Prob, 3>, 3> predictor{};
  std::array<std::array<internal::SIntContexts, 3>, 3>
      residual{};  // [axis][class of the last residual]
};

// The reference of a table: the table before it in the stream with the same axis (for G and B
// the previous channel's, for R the previous slice's B), usable for steps when of the same size.
struct Reference {
  const std::vector<std::uint32_t>* codes = nullptr;
  std::uint32_t span = 0;
};

inline int residual_class(std::int64_t e) {
  const std::int64_t a = e < 0 ? -e : e;
  return a == 0 ? 0 : a <= 2 ? 1 : 2;
}

inline std::int64_t floor_div(std::int64_t a, std::int64_t b) {  // b > 0
  const std::int64_t q = a / b;
  return (a % b != 0 && a < 0) ? q - 1 : q;
}

// The prediction of code i (before clamping): spec 4.7's table, integer arithmetic only.
inline std::int64_t predict(int mode, const std::vector<std::uint32_t>& q, std::size_t i,
                            const Reference& ref, std::uint32_t span, std::int64_t first) {
  if (i == 0) return first;
  const std::int64_t prev = q[i - 1];
  switch (mode) {
    case kPredictLinear:
      return i >= 2 ? 2 * prev - std::int64_t(q[i - 2]) : prev;
    case kPredictRefStep:
      return prev + std::int64_t((*ref.codes)[i]) - std::int64_t((*ref.codes)[i - 1]);
    case kPredictRefScaled: {
      if (span == 0) return prev;
      const std::int64_t d = std::int64_t((*ref.codes)[i]) - std::int64_t((*ref.codes)[i - 1]);
      // round(d x span_ref / span), halves up
      return prev + floor_div(2 * d * std::int64_t(ref.span) + span, 2 * std::int64_t(span));
    }
    default:
      return prev;
  }
}

inline std::int64_t clamp_code(std::int64_t p, std::int64_t top) {
  return std::clamp<std::int64_t>(p, 0, top);
}

// The first code's prediction: the reference's first code, or the top code (the peak) without one.
inline std::int64_t first_prediction(const std::vector<std::uint32_t>* previous_same_axis,
                                     std::int64_t top) {
  return previous_same_axis && !previous_same_axis->empty() ? (*previous_same_axis)[0] : top;
}

template <class F>
void for_each_component(const std::vector<Slice>& slices, F f) {
  for (std::size_t s = 0; s < slices.size(); ++s) {
    for (int c = 0; c < kChannels; ++c) {
      const ChannelSlice& ch = slices[s].channel[std::size_t(c)];
      for (int k = 0; k < ch.components(); ++k) f(s, c, k);
    }
  }
}

}  // namespace cbrdf::base_marginals
