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
  auto by_bytes = encode_to_target(*table, base, {3000, 0});
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
  auto by_psnr = encode_to_target(*table, base, {0, goal});
  ASSERT_TRUE(by_psnr.ok());
  EXPECT_TRUE(by_psnr->met);
  EXPECT_GE(by_psnr->chosen.psnr_tonemapped, goal);
  for (const RateCandidate& c : by_psnr->tried) {
    if (c.psnr_tonemapped >= goal) {
      EXPECT_GE(c.bytes, by_psnr->chosen.bytes);
    }
  }
  // 3 dB less for fewer bytes.
  EXPECT_LT(by_psnr->chosen.bytes, by_bytes->chosen.bytes);
  // The decoded file is what was measured.
  auto decoded = decode_model(by_psnr->encoded.bytes);
  ASSERT_TRUE(decoded.ok());
  EXPECT_EQ(decoded->slices.size(), std::size_t(by_psnr->chosen.slices));
}

TEST(RateControl, UnreachableTargetsReportTheClosestAndBadTargetsAreRefused) {
  auto table = make_sample("lambertian");
  ASSERT_TRUE(table.ok());
  EncoderSettings base;
  base.fit.threads = 2;
  auto tiny = encode_to_target(*table, base, {10, 0});
  ASSERT_TRUE(tiny.ok());
  EXPECT_FALSE(tiny->met);
  for (const RateCandidate& c : tiny->tried) EXPECT_GE(c.bytes, tiny->chosen.bytes);
  EXPECT_EQ(encode_to_target(*table, base, {0, 0}).status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(encode_to_target(*table, base, {100, 40}).status().code(),
            ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace cbrdf
