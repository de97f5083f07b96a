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
  // Both component counts were tried, the first at several bit depths.
  int k1 = 0, k2 = 0;
  for (const RateCandidate& c : by_bytes->tried) (c.components == 1 ? k1 : k2) += 1;
  EXPECT_GT(k1, 2);
  EXPECT_GT(k2, 0);
}

// The search's economy: one fit per (slice count, component count), each component count
// continuing the factorization of the one before; bits bisected; larger counts not fitted once the
// target is bracketed.
TEST(RateControl, SearchReusesFitsAndStopsWhenBracketed) {
  auto table = make_sample("ward");
  ASSERT_TRUE(table.ok());
  EncoderSettings base;
  base.fit.threads = 2;
  // Unreachable PSNR: every row is fitted once and measured at 16 bits; only the closest row is
  // also walked down in bits, while its PSNR stays saturated.
  auto all = encode_to_target(*table, base, {0, 1000, 2, {3}});
  ASSERT_TRUE(all.ok());
  EXPECT_FALSE(all->met);
  EXPECT_EQ(all->fits, 2);
  ASSERT_GE(all->tried.size(), 2u);
  EXPECT_EQ(all->tried[0].bits, 16);
  EXPECT_EQ(all->tried[1].bits, 16);
  for (std::size_t i = 2; i < all->tried.size(); ++i) {
    EXPECT_EQ(all->tried[i].bits, 17 - int(i));
    EXPECT_EQ(all->tried[i].components, all->tried[all->tried.size() > 2 ? 2 : 0].components);
  }
  for (const RateCandidate& c : all->tried) {
    EXPECT_LE(c.psnr_tonemapped, all->chosen.psnr_tonemapped);
  }
  // The 2-component fit spent only the sweeps of its second component: those of one fit at 2.
  EncoderSettings two = base;
  set_counts({3, false}, {2, false}, &two.fit);
  auto fit2 = encode_table(*table, two);
  ASSERT_TRUE(fit2.ok());
  long long sweeps = 0;
  for (const auto& s : fit2->report.slices) {
    for (const ChannelSliceFit& f : s) sweeps += f.hals_sweeps;
  }
  EXPECT_EQ(all->hals_sweeps, sweeps);
  // The chosen file is the one encode_table makes at its setting.
  EncoderSettings chosen = base;
  set_counts({3, false}, {all->chosen.components, false}, &chosen.fit);
  chosen.container.bits = all->chosen.bits;
  auto direct = encode_table(*table, chosen);
  ASSERT_TRUE(direct.ok());
  EXPECT_EQ(all->encoded.bytes, direct->bytes);

  // A budget below anything: 3 slices at one component and 6 bits are over it, so neither more
  // components nor 6 slices are fitted.
  auto tiny = encode_to_target(*table, base, {10, 0, 2, {3, 6}});
  ASSERT_TRUE(tiny.ok());
  EXPECT_FALSE(tiny->met);
  EXPECT_EQ(tiny->fits, 1);
  EXPECT_EQ(tiny->tried.size(), 1u);

  // A PSNR reached at 6 bits by 3 slices and one component: nothing else can have fewer bytes.
  auto low = encode_to_target(*table, base, {0, 1.0, 2, {3, 6}});
  ASSERT_TRUE(low.ok());
  EXPECT_TRUE(low->met);
  EXPECT_EQ(low->chosen.slices, 3);
  EXPECT_EQ(low->chosen.components, 1);
  EXPECT_EQ(low->chosen.bits, 6);
  EXPECT_EQ(low->fits, 1);

  // A budget inside the bit range: bisected, a handful of settings per row, not eleven.
  auto mid = encode_to_target(*table, base, {3000, 0, 1, {3}});
  ASSERT_TRUE(mid.ok());
  EXPECT_TRUE(mid->met);
  EXPECT_LE(mid->tried.size(), 6u);
  EXPECT_GE(mid->tried.size(), 2u);
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
