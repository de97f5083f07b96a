// SPDX-License-Identifier: MIT
// The real materials (../shared, made into MERL files by make-merl.sh): each one reads, its
// not-measured mask is exactly the below-horizon geometry, and it round-trips byte for byte.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>

#include "cbrdf/file_io.h"
#include "cbrdf/merl_io.h"
#include "test_support.h"

namespace cbrdf {
namespace {
namespace fs = std::filesystem;
using testing::real_material_names;
using testing::real_materials_dir;
using testing::TempDir;

constexpr std::uint64_t kReadLimit = std::uint64_t{1} << 30;

#define CBRDF_SKIP_WITHOUT_REAL_DATA()                                                         \
  if (real_materials_dir().empty()) {                                                          \
    GTEST_SKIP() << "real materials unavailable: " CBRDF_SHARED_DIR                            \
                    "/data/nbrdf-merl or tools/make-merl.sh missing (or make-merl.sh failed)"; \
  }

TEST(RealDataMerl, AllTwentyMaterialsArePresent) {
  CBRDF_SKIP_WITHOUT_REAL_DATA();
  EXPECT_EQ(real_material_names().size(), 20u);
}

TEST(RealDataMerl, MaskIsHorizonAndRoundTripIsByteExact) {
  CBRDF_SKIP_WITHOUT_REAL_DATA();
  TempDir tmp;
  for (const std::string& name : real_material_names()) {
    SCOPED_TRACE(name);
    const fs::path src = real_materials_dir() / (name + ".binary");
    MerlInfo info;
    auto table = read_merl(src, {}, &info);
    ASSERT_TRUE(table.ok()) << table.status().message();
    EXPECT_FALSE(info.folded_from_360);

    const HorizonMaskCheck mask = check_horizon_mask(*table);
    EXPECT_TRUE(mask.matches()) << mask.mismatches << " mismatches, the first at channel "
                                << mask.first_channel << " index " << mask.first_index;

    const MerlStats stats = merl_stats(*table);
    for (const MerlChannelStats& c : stats.channel) {
      EXPECT_GT(c.measured, kBinsPerChannel / 2);
      EXPECT_GE(c.min, 0.0);
      EXPECT_GT(c.max, c.mean);
      EXPECT_GT(c.mean, 0.0);
    }

    const fs::path out = tmp / (name + ".binary");
    const Status written = write_merl(out, *table);
    ASSERT_TRUE(written.ok()) << written.message();
    auto original = read_file(src, kReadLimit);
    auto copy = read_file(out, kReadLimit);
    ASSERT_TRUE(original.ok() && copy.ok());
    EXPECT_EQ(copy->size(), original->size());
    EXPECT_TRUE(*copy == *original) << "write_merl(read_merl(file)) differs from the file";
    fs::remove(out);
  }
}

// The NBRDF networks are not reciprocal (bins k and k+180 of a 360-bin file differ by about 2% at
// the median), so the folded table is not the 180-bin file: it is the 180-bin file averaged with
// the k+180 half. This checks that on real data, using the 180-bin file for the k half.
TEST(RealDataMerl, Phi360FileFoldsOntoThe180FileGrid) {
  CBRDF_SKIP_WITHOUT_REAL_DATA();
  const std::string name = "gold-metallic-paint";
  const fs::path tool = real_materials_dir() / ".nbrdf2merl";
  const fs::path nbrdf = fs::path(CBRDF_SHARED_DIR) / "data" / "nbrdf-merl" / (name + ".nbrdf");
  ASSERT_TRUE(fs::exists(tool)) << tool;
  ASSERT_TRUE(fs::exists(nbrdf)) << nbrdf;
  TempDir tmp;
  const fs::path full = tmp / (name + "-360.binary");
  const std::string cmd =
      "'" + tool.string() + "' '" + nbrdf.string() + "' '" + full.string() + "' --phi 360";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;

  MerlInfo info;
  auto folded = read_merl(full, {}, &info);
  ASSERT_TRUE(folded.ok()) << folded.status().message();
  EXPECT_TRUE(info.folded_from_360);
  EXPECT_EQ(info.dims, (std::array<std::int32_t, 3>{90, 90, 360}));
  auto reference = read_merl(real_materials_dir() / (name + ".binary"));
  ASSERT_TRUE(reference.ok()) << reference.status().message();
  auto raw = read_file(full, kReadLimit);
  ASSERT_TRUE(raw.ok()) << raw.status().message();
  const auto raw360 = [&](int c, int th, int td, int phi) {
    const std::size_t i = std::size_t(phi) + 360 * (std::size_t(td) + 90 * std::size_t(th));
    double v;
    std::memcpy(&v, raw->data() + kMerlHeaderBytes + (std::size_t(c) * 2 * kBinsPerChannel + i) * 8,
                8);
    return v;
  };

  // The premise of folding: bin k of the 360-bin file is bin k of the 180-bin file.
  std::size_t lower_half_differs = 0, wrong = 0;
  std::size_t averaged = 0, one_side = 0, neither = 0;
  for (int c = 0; c < kChannels; ++c) {
    for (int th = 0; th < kThetaHBins; ++th) {
      for (int td = 0; td < kThetaDBins; ++td) {
        for (int k = 0; k < kPhiDBins; ++k) {
          const std::size_t i = merl_index(th, td, k);
          const double ref = reference->stored(c, i), hi = raw360(c, th, td, k + 180);
          const double lo = raw360(c, th, td, k), got = folded->stored(c, i);
          lower_half_differs += std::memcmp(&ref, &lo, 8) != 0;
          double want;
          if (ref >= 0 && hi >= 0) {
            want = 0.5 * (ref + hi);
            ++averaged;
          } else if (ref >= 0 || hi >= 0) {
            want = ref >= 0 ? ref : hi;
            ++one_side;
          } else {
            want = ref;
            ++neither;
          }
          wrong += !(std::abs(got - want) <= 1e-12 * std::abs(want)) && got != want;
        }
      }
    }
  }
  EXPECT_EQ(lower_half_differs, 0u);
  EXPECT_EQ(wrong, 0u);
  EXPECT_EQ(info.fold_averaged, averaged);
  EXPECT_EQ(info.fold_one_side, one_side);
  EXPECT_EQ(info.fold_neither, neither);
  RecordProperty("fold_max_rel_diff", std::to_string(info.fold_max_rel_diff));
}

}  // namespace
}  // namespace cbrdf
