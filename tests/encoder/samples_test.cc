// SPDX-License-Identifier: MIT
#include "cbrdf/samples.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <string>
#include <vector>

#include "cbrdf/coords.h"
#include "cbrdf/merl_io.h"
#include "test_support.h"

namespace cbrdf {
namespace {

constexpr double kPi = std::numbers::pi;

// Every sample table, built once for the whole test program.
const BrdfTable& sample_table(std::string_view name) {
  static std::map<std::string, BrdfTable, std::less<>> cache;
  auto it = cache.find(name);
  if (it == cache.end()) {
    Expected<BrdfTable> t = make_sample(name);
    EXPECT_TRUE(t.ok()) << t.status().message();
    it = cache.emplace(std::string(name), t.ok() ? std::move(t).value() : BrdfTable()).first;
  }
  return it->second;
}

// The fraction of a channel's theta_h marginal (sum of physical values over measured bins, the
// way the copula fit builds it) in the first `bins` theta_h bins.
double theta_h_fraction(const BrdfTable& t, int channel, int bins) {
  double head = 0, total = 0;
  for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
    if (!t.measured(channel, i)) continue;
    const double v = t.physical(channel, i);
    total += v;
    if (merl_bin(i).theta_h < bins) head += v;
  }
  return head / total;
}

// Only analytic samples have an AnalyticBrdf.
std::vector<SampleInfo> analytic_samples() {
  std::vector<SampleInfo> out;
  for (const SampleInfo& s : sample_materials()) {
    if (s.kind == SampleKind::kAnalytic) out.push_back(s);
  }
  return out;
}

TEST(Samples, CatalogueNamesTheRequiredMaterials) {
  std::set<std::string> names;
  for (const SampleInfo& s : sample_materials()) {
    EXPECT_FALSE(s.description.empty()) << s.name;
    EXPECT_EQ(s.description.find('\n'), std::string_view::npos) << s.name;
    EXPECT_TRUE(names.insert(std::string(s.name)).second) << "duplicate " << s.name;
    EXPECT_EQ(sample_brdf(s.name).ok(), s.kind == SampleKind::kAnalytic) << s.name;
    EXPECT_EQ(s.source.empty(), s.kind == SampleKind::kAnalytic) << s.name;
  }
  for (const char* required :
       {"lambertian", "ggx-rough", "ggx-sharp", "ward", "plastic", "near-mirror",
        "blue-metallic-paint", "nickel", "yellow-matte-plastic", "pink-felt", "alum-bronze",
        "red-specular-plastic", "gold-metallic-paint"}) {
    EXPECT_TRUE(names.count(required)) << required;
  }
}

// The measured samples come first, the copula paper's three materials leading, in a fixed order.
TEST(Samples, MeasuredSamplesComeFirst) {
  const std::span<const SampleInfo> all = sample_materials();
  const std::size_t analytic = analytic_samples().size();
  ASSERT_EQ(all.size(), analytic + 7);
  for (std::size_t i = 0; i < all.size(); ++i) {
    EXPECT_EQ(all[i].kind, i < 7 ? SampleKind::kMeasured : SampleKind::kAnalytic) << all[i].name;
  }
  EXPECT_EQ(all[0].name, "blue-metallic-paint");
  EXPECT_EQ(all[1].name, "nickel");
  EXPECT_EQ(all[2].name, "yellow-matte-plastic");
  EXPECT_EQ(sample_kind_name(SampleKind::kMeasured), "measured");
  EXPECT_EQ(sample_kind_name(SampleKind::kAnalytic), "analytic");
}

TEST(Samples, UnknownNameListsTheValidOnes) {
  const Expected<BrdfTable> t = make_sample("gold-leaf");
  ASSERT_FALSE(t.ok());
  EXPECT_EQ(t.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(t.status().message().find("'gold-leaf'"), std::string::npos);
  for (const SampleInfo& s : sample_materials()) {
    EXPECT_NE(t.status().message().find(s.name), std::string::npos) << t.status().message();
  }
  EXPECT_FALSE(sample_brdf("").ok());
}

TEST(Samples, TabulateRejectsInvalidBrdfs) {
  const Expected<BrdfTable> t = tabulate(AnalyticBrdf{{ggx({1, 1, 1}, 0.0)}});
  ASSERT_FALSE(t.ok());
  EXPECT_EQ(t.status().code(), ErrorCode::kInvalidArgument);
}

// The mask exactly where bin_below_horizon() says, stored -1 in every channel; everywhere else
// finite, non-negative values equal to the analytic BRDF at the bin's grid angles, per channel.
TEST(Samples, TablesHoldTheBrdfAtGridAnglesAndTheGeneratorMask) {
  for (const SampleInfo& s : analytic_samples()) {
    SCOPED_TRACE(std::string(s.name));
    const BrdfTable& t = sample_table(s.name);
    const AnalyticBrdf brdf = sample_brdf(s.name).value();
    std::size_t not_measured = 0, checked = 0;
    for (int i = 0; i < kThetaHBins; ++i) {
      for (int j = 0; j < kThetaDBins; ++j) {
        for (int k = 0; k < kPhiDBins; ++k) {
          const std::size_t idx = merl_index(i, j, k);
          if (bin_below_horizon(i, j, k)) {
            ++not_measured;
            for (int c = 0; c < kChannels; ++c)
              ASSERT_EQ(t.stored(c, idx), -1.0) << i << " " << j << " " << k;
            continue;
          }
          for (int c = 0; c < kChannels; ++c) {
            ASSERT_TRUE(std::isfinite(t.stored(c, idx)));
            ASSERT_GE(t.stored(c, idx), 0.0) << i << " " << j << " " << k;
          }
          if (idx % 7 != 0) continue;  // the value check on a spread-out seventh of the bins
          HalfDiff hd;
          hd.theta_h = theta_h_of(i);
          hd.theta_d = theta_d_of(j);
          hd.phi_d = phi_d_of(k);
          Vec3 wi, wo;
          from_half_diff(hd, &wi, &wo);
          double f[3];
          brdf.eval(wi, wo, f);
          for (int c = 0; c < kChannels; ++c) {
            ASSERT_NEAR(t.physical(c, idx), f[c], 1e-12 * f[c]) << i << " " << j << " " << k;
          }
          ++checked;
        }
      }
    }
    EXPECT_EQ(t.count_not_measured(), kChannels * not_measured);
    EXPECT_GT(not_measured, 0u);
    EXPECT_GT(checked, kBinsPerChannel / 10);
  }
}

// The real files' generator marks exactly the same bins not measured, with the same stored value.
TEST(Samples, MaskMatchesARealFile) {
  const std::vector<std::string> names = testing::real_material_names();
  if (names.empty()) {
    GTEST_SKIP() << "no real materials: ../shared/data/nbrdf-merl is absent";
  }
  const std::filesystem::path path = testing::real_materials_dir() / (names.front() + ".binary");
  const Expected<BrdfTable> real = read_merl(path);
  ASSERT_TRUE(real.ok()) << real.status().message();
  const BrdfTable& sample = sample_table("plastic");
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      ASSERT_EQ(real->measured(c, i), sample.measured(c, i))
          << path << " channel " << c << " bin " << i;
      if (!sample.measured(c, i)) {
        ASSERT_EQ(real->stored(c, i), sample.stored(c, i));
      }
    }
  }
}

// Colours differ per channel, so a channel mix-up anywhere downstream changes the result.
TEST(Samples, ChannelsDiffer) {
  const std::size_t specular_peak = merl_index(0, 10, 90);
  const std::size_t off_peak = merl_index(60, 30, 45);
  for (const SampleInfo& s : analytic_samples()) {
    const BrdfTable& t = sample_table(s.name);
    for (const std::size_t idx : {specular_peak, off_peak}) {
      ASSERT_TRUE(t.measured(0, idx));
      const double r = t.physical(0, idx), g = t.physical(1, idx), b = t.physical(2, idx);
      EXPECT_TRUE(r != g && g != b && r != b) << s.name << " bin " << idx;
    }
  }
}

TEST(Samples, LambertianIsConstantPerChannel) {
  const BrdfTable& t = sample_table("lambertian");
  const AnalyticBrdf brdf = sample_brdf("lambertian").value();
  ASSERT_EQ(brdf.lobes.size(), 1u);
  for (int c = 0; c < kChannels; ++c) {
    const double expected = brdf.lobes[0].rgb[c] / kPi;
    std::size_t measured = 0;
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (!t.measured(c, i)) continue;
      ++measured;
      ASSERT_EQ(t.stored(c, i), expected / kMerlScale[c]) << "channel " << c << " bin " << i;
    }
    EXPECT_GT(measured, kBinsPerChannel / 2);
  }
}

// Near-mirror GGX (alpha 0.015) has half its peak at tan(theta_h) = alpha sqrt(sqrt(2) - 1), about
// 0.55 deg, i.e. theta_h bin 7; D falls as theta_h^-4 beyond. With equal weight per bin (the
// marginal is a sum over bins, not a solid-angle integral), theta_h bins 0-4 (up to 0.18 deg) held
// 62.0% of the red marginal when measured, bins 0-9 (up to 1.0 deg) 96.2%. A diffuse table puts
// 7.3% / 14.6% there, a rough GGX 15.8% / 31.6%. The bounds pin the measured values from both
// sides.
TEST(Samples, NearMirrorThetaHMarginalIsExtremelySkewed) {
  const BrdfTable& mirror = sample_table("near-mirror");
  for (int c = 0; c < kChannels; ++c) {
    const double first5 = theta_h_fraction(mirror, c, 5), first10 = theta_h_fraction(mirror, c, 10);
    EXPECT_GT(first5, 0.58) << "channel " << c;
    EXPECT_LT(first5, 0.66) << "channel " << c;
    EXPECT_GT(first10, 0.95) << "channel " << c;
    EXPECT_LT(first10, 0.975) << "channel " << c;
  }
  EXPECT_LT(theta_h_fraction(sample_table("ggx-rough"), 0, 10), 0.35);
  EXPECT_LT(theta_h_fraction(sample_table("lambertian"), 0, 10), 0.16);
  // The peak is in bin 0, and its value is the closed form F0 / (4 pi alpha^2) at theta_d = 0.
  const AnalyticBrdf brdf = sample_brdf("near-mirror").value();
  const double alpha = brdf.lobes[0].shape;
  for (int c = 0; c < kChannels; ++c) {
    EXPECT_NEAR(mirror.physical(c, merl_index(0, 0, 0)),
                brdf.lobes[0].rgb[c] / (4 * kPi * alpha * alpha), 1e-9 * mirror.physical(c, 0));
  }
}

// Each sample reflects at most what it receives, at every outgoing angle.
TEST(Samples, SamplesConserveEnergy) {
  for (const SampleInfo& s : analytic_samples()) {
    const AnalyticBrdf brdf = sample_brdf(s.name).value();
    for (double deg : {0.0, 30.0, 60.0, 80.0, 88.0}) {
      const Vec3 wo{std::sin(deg * kPi / 180), 0, std::cos(deg * kPi / 180)};
      const std::array<double, 3> a = directional_albedo(brdf, wo, 4);
      for (int c = 0; c < kChannels; ++c) {
        EXPECT_LE(a[c], 1.0) << s.name << " theta_o " << deg << " channel " << c;
        EXPECT_GT(a[c], 0.0) << s.name << " theta_o " << deg << " channel " << c;
      }
    }
  }
}

}  // namespace
}  // namespace cbrdf
