// SPDX-License-Identifier: MIT
#include "cbrdf/rate_control.h"

#include <gtest/gtest.h>

#include "cbrdf/samples.h"

namespace cbrdf {
namespace {

TEST(RateControl, ByteBudgetAndPsnrTargetPickTheBestSettingTried) {
  auto table = make_sample("ward");
  ASSERT_TRUE(table.ok());
  EncoderSettings base;
  base.fit.threads = 2;
  // Mixtures up to 2 components are part of the search (4 and six slice counts by default; fewer
  // keep the test short).
  auto by_bytes = encode_to_target(*table, base, {3000, 0, 2, {3}});
  ASSERT_TRUE(by_bytes.ok()) << by_bytes.status().message();
  EXPECT_TRUE(by_bytes->met);
  EXPECT_LE(by_bytes->encoded.bytes.size(), 3000u);
  EXPECT_EQ(double(by_bytes->encoded.bytes.size()), by_bytes->chosen.bytes);
  for (const RateCandidate& c : by_bytes->tried) {
    if (c.bytes <= 3000) {
      EXPECT_LE(c.psnr_tonemapped, by_bytes->chosen.psnr_tonemapped);
    }
  }
  const double goal = by_bytes->chosen.psnr_tonemapped - 3.0;
  auto by_psnr = encode_to_target(*table, base, {0, goal, 2, {3}});
  ASSERT_TRUE(by_psnr.ok());
  EXPECT_TRUE(by_psnr->met);
  EXPECT_GE(by_psnr->chosen.psnr_tonemapped, goal);
  for (const RateCandidate& c : by_psnr->tried) {
    if (c.psnr_tonemapped >= goal) {
      EXPECT_GE(c.bytes, by_psnr->chosen.bytes);
    }
  }
  // 3 dB less never costs more bytes.
  EXPECT_LE(by_psnr->chosen.bytes, by_bytes->chosen.bytes);
  // The decoded file is what was measured.
  auto decoded = decode_model(by_psnr->encoded.bytes);
  ASSERT_TRUE(decoded.ok());
  EXPECT_EQ(decoded->slices.size(), std::size_t(by_psnr->chosen.slices));
  EXPECT_EQ(decoded->slices[0].channel[0].components(), by_psnr->chosen.components);
  // Both component counts were tried, each at several bit depths.
  int k1 = 0, k2 = 0;
  for (const RateCandidate& c : by_bytes->tried) (c.components == 1 ? k1 : k2) += 1;
  EXPECT_GT(k1, 2);
  EXPECT_GT(k2, 0);
}

TEST(RateControl, UnreachableTargetsReportTheClosestAndBadTargetsAreRefused) {
  auto table = make_sample("lambertian");
  ASSERT_TRUE(table.ok());
  EncoderSettings base;
  base.fit.threads = 2;
  auto tiny = encode_to_target(*table, base, {10, 0, 1, {3, 6}});
  ASSERT_TRUE(tiny.ok());
  EXPECT_FALSE(tiny->met);
  for (const RateCandidate& c : tiny->tried) EXPECT_GE(c.bytes, tiny->chosen.bytes);
  EXPECT_EQ(encode_to_target(*table, base, {0, 0}).status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(encode_to_target(*table, base, {100, 40}).status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(encode_to_target(*table, base, {100, 0, 0}).status().message(),
            "max_components 0 is outside 1 to 8");
  EXPECT_EQ(encode_to_target(*table, base, {100, 0, 1, {}}).status().message(),
            "no slice counts to search");
}

}  // namespace
}  // namespace cbrdf
