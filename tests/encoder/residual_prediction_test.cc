// SPDX-License-Identifier: MIT
// RESD's predicted codes (spec/container.md 4.6, "Predicted codes", predictor 3): the prediction
// as the spec writes it (hand-computed bins, row steps scaled both ways, floor division), exact
// round trips under every row-shift difference, and the writer's fit finding what is there.
#include "bitstream/residual_prediction.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "bitstream/chunks.h"
#include "bitstream/residual_prediction_fit.h"

namespace cbrdf::internal {
namespace {

constexpr std::size_t bin(int c, int h, int d, int p) {
  return std::size_t(c) * kBinsPerChannel +
         (std::size_t(h) * kThetaDBins + std::size_t(d)) * kPhiDBins + std::size_t(p);
}
constexpr std::size_t row(int h, int d) {
  return std::size_t(h) * kThetaDBins + std::size_t(d);
}

CodePrediction coefficients(int groups) {
  CodePrediction p;
  p.groups = groups;
  p.coef.assign(std::size_t(kChannels * groups), {0, 0, 0});
  return p;
}

// Mode 2 (one group), shifts 2, 0 and 3 on rows (0, 1), (1, 1), (2, 1): the neighbour of the
// bin at theta_h 1 is scaled up by 2^2, that of the bin at theta_h 2 down by 2^3, rounding down.
TEST(ResidualPrediction, FollowsTheSpecsFormula) {
  Residual res;
  res.row_shift.assign(kResidualRows, 0);
  res.row_shift[row(0, 1)] = 2;
  res.row_shift[row(2, 1)] = 3;
  NotMeasured mask;  // every bin measured
  std::vector<std::int32_t> q(kMaskBits, 0);
  q[bin(1, 0, 1, 5)] = 3;   // G, the slab before: U' = 3 x 4 = 12
  q[bin(0, 1, 1, 5)] = -9;  // R, same bin: X = -9
  q[bin(0, 0, 1, 5)] = -5;  // R, the slab before: XU' = -20
  q[bin(1, 1, 1, 5)] = 40;  // G's code
  q[bin(0, 2, 1, 5)] = 11;  // R at theta_h 2: U' = floor(-9 / 8) = -2
  CodePrediction p = coefficients(1);
  p.at(0, 0) = {256, 0, 0};
  p.at(1, 0) = {128, 256, -64};  // 0.5 U' + X - 0.25 XU'
  std::vector<std::int32_t> r(kMaskBits, 0);
  ASSERT_TRUE(predict_codes(q.data(), mask, res, p, r.data()));
  // G: (128 x 12 + 256 x -9 - 64 x -20 + 128) >> 8 = floor(640 / 256) = 2.
  EXPECT_EQ(r[bin(1, 1, 1, 5)], 40 - 2);
  // R at theta_h 2: (256 x -2 + 128) >> 8 = floor(-384 / 256) = -2.
  EXPECT_EQ(r[bin(0, 2, 1, 5)], 11 + 2);
  // R at theta_h 1: U' = -5 x 4 = -20, predicted -20.
  EXPECT_EQ(r[bin(0, 1, 1, 5)], -9 + 20);
  // theta_h 0 has no slab before; R no channel before: its first slab is coded as it is.
  EXPECT_EQ(r[bin(0, 0, 1, 5)], -5);
  std::vector<std::int32_t> back = r;
  ASSERT_TRUE(unpredict_codes(back.data(), mask, res, p, 0).ok());
  EXPECT_EQ(back, q);
}

// Random codes under row shifts 0..10 (differences up to 10 both ways, beyond the limit of 8
// where a neighbour drops out), mode 3's four groups with distinct coefficients, and not-measured
// bins (code 0, never predicted): the decoder's undoing gives the codes back. Codes up to 2^12
// take the decoder's 32-bit rows, up to 2^18 mostly its 64-bit ones; both must agree with the
// writer's per-bin arithmetic.
void expect_round_trip(int max_bits) {
  Residual res;
  res.levels = 3;
  res.row_shift.resize(kResidualRows);
  for (int h = 0; h < kThetaHBins; ++h) {
    for (int d = 0; d < kThetaDBins; ++d) res.row_shift[row(h, d)] = std::uint8_t((h * 5 + d) % 11);
  }
  NotMeasured mask;
  for (std::size_t b = 0; b < kMaskBits; b += 7) mask.bits[b >> 6] |= std::uint64_t{1} << (b & 63);
  std::vector<std::int32_t> q(kMaskBits, 0);
  std::uint32_t lcg = 7;
  for (std::size_t b = 0; b < kMaskBits; ++b) {
    if (mask_bit(mask.bits, b)) continue;
    lcg = lcg * 1664525u + 1013904223u;
    const std::int32_t v =
        std::int32_t((lcg >> 8) & ((1u << ((lcg >> 3) % std::uint32_t(max_bits + 1))) - 1));
    q[b] = (lcg & 1) ? -v : v;
  }
  CodePrediction p = coefficients(prediction_groups(res));
  ASSERT_EQ(p.groups, 4);
  for (int c = 0; c < kChannels; ++c) {
    for (int g = 0; g < p.groups; ++g) {
      p.at(c, g) = {std::int16_t(200 - 30 * g), std::int16_t(c > 0 ? 180 + g : 0),
                    std::int16_t(c > 0 ? -150 + 7 * g : 0)};
    }
  }
  std::vector<std::int32_t> r(kMaskBits, 0);
  ASSERT_TRUE(predict_codes(q.data(), mask, res, p, r.data()));
  EXPECT_NE(r, q);
  SCOPED_TRACE(max_bits);
  for (std::size_t b = 0; b < kMaskBits; b += 7) EXPECT_EQ(r[b], 0);
  ASSERT_TRUE(unpredict_codes(r.data(), mask, res, p, 0).ok());
  EXPECT_EQ(r, q);
}

TEST(ResidualPrediction, RoundTripsUnderEveryRowShiftDifference) {
  expect_round_trip(12);
  expect_round_trip(18);
}

// The writer's fit: G and B equal to R's codes get b = 1 and code zeros; codes without relation
// across slabs or channels get no coefficient at all.
TEST(ResidualPrediction, FitFindsWhatIsThereAndNothingElse) {
  Residual res;
  res.levels = 3;
  res.row_shift.assign(kResidualRows, 0);
  NotMeasured mask;
  std::vector<std::int32_t> q(kMaskBits, 0), noise(kMaskBits, 0);
  std::uint32_t lcg = 11;
  for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
    for (int c = 0; c < kChannels; ++c) {
      lcg = lcg * 1664525u + 1013904223u;
      noise[std::size_t(c) * kBinsPerChannel + i] = std::int32_t((lcg >> 9) % 201) - 100;
    }
    for (int c = 0; c < kChannels; ++c) q[std::size_t(c) * kBinsPerChannel + i] = noise[i];
  }
  const CodePrediction alike = fit_prediction(q.data(), mask, res);
  for (int g = 0; g < alike.groups; ++g) {
    EXPECT_EQ(alike.at(0, g)[0], 0) << g;  // R's slabs are unrelated
    for (int c = 1; c < kChannels; ++c) {
      EXPECT_NEAR(alike.at(c, g)[1], 256, 2) << c << " " << g;
      EXPECT_NEAR(alike.at(c, g)[0], 0, 2) << c << " " << g;
      EXPECT_NEAR(alike.at(c, g)[2], 0, 2) << c << " " << g;
    }
  }
  std::vector<std::int32_t> r(kMaskBits, 0);
  ASSERT_TRUE(predict_codes(q.data(), mask, res, alike, r.data()));
  std::size_t zeros = 0;
  for (std::size_t b = kBinsPerChannel; b < kMaskBits; ++b) zeros += r[b] == 0 ? 1 : 0;
  EXPECT_GT(zeros, 2 * kBinsPerChannel * 99 / 100);
  EXPECT_FALSE(fit_prediction(noise.data(), mask, res).any());
}

}  // namespace
}  // namespace cbrdf::internal
