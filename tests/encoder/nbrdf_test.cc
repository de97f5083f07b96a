// SPDX-License-Identifier: MIT
// The NBRDF evaluator (codec/encoder/src/nbrdf.h) and the built-in measured samples: the parser's
// errors, the network's layout and arithmetic on a hand-made network, the embedded weights, the
// tables' mask and values, bit-for-bit determinism, and agreement with ../shared's generator.
#include "nbrdf.h"

#include <gtest/gtest.h>
#include <xxhash.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "cbrdf/coords.h"
#include "cbrdf/merl_io.h"
#include "cbrdf/parallel.h"
#include "cbrdf/samples.h"
#include "embedded_files.h"
#include "test_support.h"

namespace cbrdf::internal {
namespace {
namespace fs = std::filesystem;

// Offsets of the blocks in file order: W1[6][21] b1[21] W2[21][21] b2[21] W3[21][3] b3[3].
constexpr std::size_t kW1 = 0, kB1 = 126, kW2 = 147, kB2 = 588, kW3 = 609, kB3 = 672;

std::vector<std::uint8_t> to_bytes(const std::vector<float>& weights) {
  std::vector<std::uint8_t> out;
  for (float w : weights) {
    const std::uint32_t u = std::bit_cast<std::uint32_t>(w);
    for (int b = 0; b < 4; ++b) out.push_back(std::uint8_t(u >> (8 * b)));  // little-endian
  }
  return out;
}

std::span<const std::uint8_t> embedded(std::string_view name) {
  for (const EmbeddedFile& f : embedded_nbrdf_files()) {
    if (f.name == name) return f.bytes;
  }
  ADD_FAILURE() << name << " is not embedded";
  return {};
}

const BrdfTable& nickel() {
  static const BrdfTable table = make_sample("nickel").value();
  return table;
}

std::uint64_t hash_of(const BrdfTable& t) {
  const std::vector<std::uint8_t> file = serialize_merl(t);
  return XXH64(file.data(), file.size(), 0);
}

TEST(Nbrdf, ParserRejectsWrongSizes) {
  const std::vector<std::uint8_t> good(embedded("nickel").begin(), embedded("nickel").end());
  ASSERT_EQ(good.size(), kNbrdfBytes);
  ASSERT_TRUE(parse_nbrdf(good, "nickel").ok());

  for (std::size_t size : {std::size_t(0), std::size_t(4), kNbrdfBytes - 1}) {
    const auto r = parse_nbrdf(std::span(good).first(size), "short.nbrdf");
    ASSERT_FALSE(r.ok()) << size;
    EXPECT_EQ(r.status().code(), ErrorCode::kTruncated);
    EXPECT_TRUE(testing::contains(r.status().message(), "short.nbrdf: " + std::to_string(size) +
                                                            " bytes; an NBRDF weight file holds "
                                                            "exactly 2700 bytes"))
        << r.status().message();
  }
  std::vector<std::uint8_t> longer = good;
  longer.push_back(0);
  const auto r = parse_nbrdf(longer, "long.nbrdf");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), ErrorCode::kCorrupt);
  EXPECT_TRUE(testing::contains(r.status().message(), "long.nbrdf: 2701 bytes"))
      << r.status().message();
}

TEST(Nbrdf, ParserRejectsNonFiniteWeights) {
  struct Case {
    std::size_t index;
    float value;
    const char* says;
  };
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  for (const Case& c : {Case{0, nan, "weight 0 (W1[0][0], byte offset 0) is NaN"},
                        Case{kW2 + 22, -inf, "weight 169 (W2[1][1], byte offset 676) is infinite"},
                        Case{kB3 + 2, nan, "weight 674 (b3[2], byte offset 2696) is NaN"}}) {
    std::vector<float> w(kNbrdfFloats, 0.25f);
    w[c.index] = c.value;
    const auto r = parse_nbrdf(to_bytes(w), "bad.nbrdf");
    ASSERT_FALSE(r.ok()) << c.index;
    EXPECT_EQ(r.status().code(), ErrorCode::kNumeric);
    EXPECT_EQ(r.status().message(), std::string("bad.nbrdf: ") + c.says);
  }
}

// A network with a few hand-set weights checks the layout ((inputs, outputs) row-major), the
// ReLUs, the exp(y) - 1 output and the clamp of negative outputs to 0.
TEST(Nbrdf, HandMadeNetworkEvaluatesAsTheFormatSays) {
  std::vector<float> w(kNbrdfFloats, 0.0f);
  w[kW1 + 2 * 21 + 0] = 1.0f;   // hidden1[0] = relu(h.z)
  w[kW1 + 0 * 21 + 1] = -1.0f;  // hidden1[1] = relu(-h.x) = 0 for theta_h > 0
  w[kB1 + 2] = -0.5f;           // hidden1[2] = relu(d.z - 0.5)
  w[kW1 + 5 * 21 + 2] = 1.0f;
  w[kW2 + 0 * 21 + 0] = 2.0f;  // hidden2[0] = relu(2 hidden1[0] + 9 hidden1[1])
  w[kW2 + 1 * 21 + 0] = 9.0f;
  w[kW2 + 2 * 21 + 3] = 1.0f;  // hidden2[3] = relu(hidden1[2] + 0.125)
  w[kB2 + 3] = 0.125f;
  w[kW3 + 0 * 3 + 1] = 1.0f;   // y_g = hidden2[0]
  w[kW3 + 0 * 3 + 2] = -1.0f;  // y_b = -hidden2[0] + 3 hidden2[3] + 0.5
  w[kW3 + 3 * 3 + 2] = 3.0f;
  w[kB3 + 2] = 0.5f;
  w[kB3 + 0] = -0.25f;  // y_r < 0: exp(y) - 1 < 0, clamped to 0
  const NbrdfNet net = parse_nbrdf(to_bytes(w), "hand").value();

  for (const auto& [th, td, pd] : {std::array<double, 3>{0.3, 0.2, 1.0}, {1.2, 0.9, 2.5}}) {
    const auto x = nbrdf_input(th, td, pd);
    EXPECT_EQ(x[0], std::sin(th));
    EXPECT_EQ(x[1], 0.0);
    EXPECT_EQ(x[2], std::cos(th));
    EXPECT_EQ(x[3], std::sin(td) * std::cos(pd));
    EXPECT_EQ(x[4], std::sin(td) * std::sin(pd));
    EXPECT_EQ(x[5], std::cos(td));
    double rgb[3];
    eval_nbrdf(net, x, rgb);
    const double h2_0 = 2 * std::cos(th);
    const double h2_3 = std::max(std::cos(td) - 0.5, 0.0) + 0.125;
    EXPECT_EQ(rgb[0], 0.0);
    EXPECT_DOUBLE_EQ(rgb[1], std::expm1(h2_0));
    EXPECT_DOUBLE_EQ(rgb[2], std::max(std::expm1(-h2_0 + 3 * h2_3 + 0.5), 0.0));
  }
}

TEST(Nbrdf, OverflowingNetworkFailsToTabulate) {
  std::vector<float> w(kNbrdfFloats, 0.0f);
  w[kB3 + 1] = 1000.0f;  // exp(1000) overflows
  const auto t = tabulate_nbrdf(parse_nbrdf(to_bytes(w), "hot").value());
  ASSERT_FALSE(t.ok());
  EXPECT_EQ(t.status().code(), ErrorCode::kNumeric);
  EXPECT_EQ(t.status().message(),
            "neural BRDF is not finite at MERL bin (theta_h 0, theta_d 0, phi_d 0)");
}

// What the library carries is exactly the repository's data/measured/NAME.nbrdf, for every
// measured sample, and only those.
TEST(Nbrdf, EmbeddedWeightsAreTheDataFolder) {
  const fs::path dir = fs::path(CBRDF_TEST_DATA_DIR) / ".." / ".." / "data" / "measured";
  std::size_t measured = 0;
  for (const SampleInfo& s : sample_materials()) {
    if (s.kind != SampleKind::kMeasured) continue;
    ++measured;
    const std::string file = testing::read_text(dir / (std::string(s.name) + ".nbrdf"));
    const std::span<const std::uint8_t> bytes = embedded(s.name);
    ASSERT_EQ(bytes.size(), file.size()) << s.name;
    EXPECT_EQ(std::memcmp(bytes.data(), file.data(), file.size()), 0) << s.name;
    EXPECT_TRUE(parse_nbrdf(bytes, s.name).ok()) << s.name;
    EXPECT_FALSE(s.source.empty()) << s.name;
  }
  EXPECT_EQ(embedded_nbrdf_files().size(), measured);
  EXPECT_GE(measured, 7u);
}

// Below the horizon exactly -1 in every channel; elsewhere finite, non-negative values equal to
// the network at the bin's grid angles; and positive almost everywhere.
TEST(Nbrdf, TableHoldsTheNetworkAtGridAnglesAndTheHorizonMask) {
  const BrdfTable& t = nickel();
  const NbrdfNet net = parse_nbrdf(embedded("nickel"), "nickel").value();
  std::size_t below = 0, zero = 0;
  for (int i = 0; i < kThetaHBins; ++i) {
    for (int j = 0; j < kThetaDBins; ++j) {
      for (int k = 0; k < kPhiDBins; ++k) {
        const std::size_t idx = merl_index(i, j, k);
        if (bin_below_horizon(i, j, k)) {
          ++below;
          for (int c = 0; c < kChannels; ++c) ASSERT_EQ(t.stored(c, idx), -1.0) << idx;
          continue;
        }
        for (int c = 0; c < kChannels; ++c) {
          ASSERT_TRUE(std::isfinite(t.stored(c, idx))) << idx;
          ASSERT_GE(t.stored(c, idx), 0.0) << idx;
          zero += t.stored(c, idx) == 0.0;
        }
        if (idx % 11 != 0) continue;
        double rgb[3];
        eval_nbrdf(net, nbrdf_input(theta_h_of(i), theta_d_of(j), phi_d_of(k)), rgb);
        for (int c = 0; c < kChannels; ++c) {
          ASSERT_EQ(t.stored(c, idx), rgb[c] / kMerlScale[c]) << idx;
        }
      }
    }
  }
  EXPECT_GT(below, 0u);
  EXPECT_EQ(t.count_not_measured(), kChannels * below);
  EXPECT_TRUE(check_horizon_mask(t).matches());
  EXPECT_EQ(zero, 0u) << "measured bins holding 0";
}

// The table's bytes are pinned (a change to the evaluator, the grid angles or the mask shows
// here), and the same with one thread as with the default pool. The hash was taken with glibc's
// libm on x86-64; another libm's sin, cos or expm1 could differ in the last bit.
TEST(Nbrdf, TableIsBitForBitDeterministic) {
  const std::uint64_t pooled = hash_of(nickel());
  EXPECT_EQ(pooled, 0xd24d573daf1ce0bfu) << std::hex << pooled;
  const int limit = thread_limit();
  set_thread_limit(1);
  const BrdfTable single = make_sample("nickel").value();
  set_thread_limit(limit);
  EXPECT_EQ(hash_of(single), pooled);
  EXPECT_TRUE(single.stored_values() == nickel().stored_values());
}

// ../shared's independent generator (make-merl.sh, nbrdf2merl.cpp) makes the same table: the same
// not-measured bins and values equal to within rounding of the angles.
TEST(Nbrdf, AgreesWithTheSharedGenerator) {
  if (testing::real_materials_dir().empty()) {
    GTEST_SKIP() << "no real materials: " CBRDF_SHARED_DIR
                    "/data/nbrdf-merl or make-merl.sh "
                    "missing (or make-merl.sh failed)";
  }
  const BrdfTable reference = read_merl(testing::real_materials_dir() / "nickel.binary").value();
  const BrdfTable& ours = nickel();
  double worst = 0;
  std::size_t differ = 0;
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      ASSERT_EQ(ours.measured(c, i), reference.measured(c, i)) << c << " " << i;
      const double a = ours.stored(c, i), b = reference.stored(c, i);
      if (!reference.measured(c, i)) {
        ASSERT_EQ(a, b);
        continue;
      }
      differ += a != b;
      if (a != b) worst = std::max(worst, std::abs(a - b) / std::max(std::abs(b), 1e-300));
    }
  }
  std::printf(
      "nickel against make-merl.sh: %zu of %zu values differ, max relative difference "
      "%.3g\n",
      differ, std::size_t(kChannels) * kBinsPerChannel, worst);
  EXPECT_LT(worst, 1e-12);
}

TEST(Nbrdf, MeasuredSampleHasNoAnalyticForm) {
  const auto b = sample_brdf("nickel");
  ASSERT_FALSE(b.ok());
  EXPECT_EQ(b.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(b.status().message(),
            "nickel is a measured sample (neural fit of MERL data); it has no analytic form");
}

}  // namespace
}  // namespace cbrdf::internal
