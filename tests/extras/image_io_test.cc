// SPDX-License-Identifier: MIT
#include "cbrdf/image_io.h"

#include <gtest/gtest.h>
#include <png.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <random>

#include "cbrdf/coords.h"
#include "cbrdf/exr_table.h"
#include "exr_channels.h"
#include "test_support.h"

namespace cbrdf {
namespace {

using cbrdf::testing::TempDir;

void write_bytes(const std::filesystem::path& p, const std::string& bytes) {
  std::ofstream out(p, std::ios::binary);
  out << bytes;
}

TEST(Exr, RoundTripIsExactInFloat32) {
  TempDir tmp;
  Image img(7, 5);  // not square, odd sizes: catches swapped strides
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-2.0f, 2.0f);
  for (float& v : img.data) v = u(rng) * std::pow(10.0f, float(int(rng() % 9) - 4));
  img.at(0, 0, 0) = 0.0f;
  img.at(6, 4, 2) = 65504.5f;  // beyond half precision: must stay float
  img.at(3, 2, 1) = 1e-30f;
  ASSERT_TRUE(write_exr(tmp / "a.exr", img).ok());
  Expected<Image> back = read_exr(tmp / "a.exr");
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->width, 7);
  EXPECT_EQ(back->height, 5);
  EXPECT_EQ(*back, img);
}

TEST(Exr, ErrorsNameTheFile) {
  TempDir tmp;
  Expected<Image> missing = read_exr(tmp / "none.exr");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().code(), ErrorCode::kNotFound);
  EXPECT_NE(missing.status().message().find("none.exr"), std::string::npos);

  write_bytes(tmp / "junk.exr", "this is not an OpenEXR file at all");
  Expected<Image> junk = read_exr(tmp / "junk.exr");
  ASSERT_FALSE(junk.ok());
  EXPECT_EQ(junk.status().code(), ErrorCode::kCorrupt);
  EXPECT_NE(junk.status().message().find("junk.exr"), std::string::npos);

  // A truncated real file fails too, and does not crash.
  Image img(16, 16);
  for (std::size_t i = 0; i < img.data.size(); ++i) img.data[i] = float(i);
  ASSERT_TRUE(write_exr(tmp / "full.exr", img).ok());
  const std::string full = cbrdf::testing::read_text(tmp / "full.exr");
  write_bytes(tmp / "cut.exr", full.substr(0, full.size() / 2));
  EXPECT_FALSE(read_exr(tmp / "cut.exr").ok());

  const Status empty = write_exr(tmp / "empty.exr", Image());
  EXPECT_EQ(empty.code(), ErrorCode::kInvalidArgument);
  EXPECT_FALSE(std::filesystem::exists(tmp / "empty.exr"));
}

TEST(Exr, LuminanceAndMissingChannels) {
  TempDir tmp;
  const std::vector<float> y = {0.25f, 4.0f, -1.0f, 7.5f, 0.0f, 1e3f};
  ASSERT_TRUE(internal::write_exr_channels(tmp / "y.exr", 3, 2, {{"Y", y.data(), 1}}, {}).ok());
  Expected<Image> grey = read_exr(tmp / "y.exr");
  ASSERT_TRUE(grey.ok()) << grey.status().message();
  for (int i = 0; i < 6; ++i) {
    for (int c = 0; c < 3; ++c) EXPECT_EQ(grey->at(i % 3, i / 3, c), y[i]) << i << " " << c;
  }
  // Only R present: G and B read as 0. String attributes come back too.
  ASSERT_TRUE(
      internal::write_exr_channels(tmp / "r.exr", 3, 2, {{"R", y.data(), 1}}, {{"note", "hello"}})
          .ok());
  Expected<Image> red = read_exr(tmp / "r.exr");
  ASSERT_TRUE(red.ok()) << red.status().message();
  EXPECT_EQ(red->at(1, 0, 0), 4.0f);
  EXPECT_EQ(red->at(1, 0, 1), 0.0f);
  EXPECT_EQ(red->at(1, 0, 2), 0.0f);
  Expected<internal::ExrChannels> raw = internal::read_exr_channels(tmp / "r.exr", {"R"}, 100);
  ASSERT_TRUE(raw.ok());
  EXPECT_EQ(raw->strings["note"], "hello");
  // The pixel limit is checked before anything is allocated.
  Expected<internal::ExrChannels> big = internal::read_exr_channels(tmp / "r.exr", {"R"}, 5);
  ASSERT_FALSE(big.ok());
  EXPECT_EQ(big.status().code(), ErrorCode::kLimit);
  EXPECT_NE(big.status().message().find("3x2"), std::string::npos);
}

TEST(Png, GreyFilesReadAsGreyRgb) {
  TempDir tmp;
  const std::vector<std::uint8_t> grey = {0, 17, 128, 255, 3, 99};
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = 3;
  png.height = 2;
  png.format = PNG_FORMAT_GRAY;
  ASSERT_TRUE(png_image_write_to_file(&png, (tmp / "g.png").c_str(), 0, grey.data(), 0, nullptr));
  Expected<Image> img = read_png(tmp / "g.png");
  ASSERT_TRUE(img.ok()) << img.status().message();
  ASSERT_EQ(img->width, 3);
  ASSERT_EQ(img->height, 2);
  for (int i = 0; i < 6; ++i) {
    for (int c = 0; c < 3; ++c) EXPECT_EQ(img->at(i % 3, i / 3, c), grey[i] / 255.0f) << i;
  }
}

TEST(Png, RoundTripOfEightBitValues) {
  TempDir tmp;
  Image img(9, 4);
  for (std::size_t i = 0; i < img.data.size(); ++i) img.data[i] = float((i * 37) % 256) / 255.0f;
  ASSERT_TRUE(write_png(tmp / "a.png", img).ok());
  Expected<Image> back = read_png(tmp / "a.png");
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(*back, img);
}

TEST(Png, QuantizesAndClamps) {
  TempDir tmp;
  Image img(5, 1);
  img.at(0, 0, 0) = 0.5f;                                     // 127.5 rounds to 128
  img.at(1, 0, 0) = 1.7f;                                     // clamps to 255
  img.at(2, 0, 0) = -0.2f;                                    // clamps to 0
  img.at(3, 0, 0) = std::numeric_limits<float>::quiet_NaN();  // 0
  img.at(4, 0, 0) = 0.1f;                                     // 25.5 rounds to 26
  ASSERT_TRUE(write_png(tmp / "q.png", img).ok());
  Expected<Image> back = read_png(tmp / "q.png");
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->at(0, 0, 0), 128.0f / 255.0f);
  EXPECT_EQ(back->at(1, 0, 0), 1.0f);
  EXPECT_EQ(back->at(2, 0, 0), 0.0f);
  EXPECT_EQ(back->at(3, 0, 0), 0.0f);
  EXPECT_EQ(back->at(4, 0, 0), 26.0f / 255.0f);
}

TEST(Png, Errors) {
  TempDir tmp;
  EXPECT_EQ(read_png(tmp / "none.png").status().code(), ErrorCode::kNotFound);
  write_bytes(tmp / "junk.png", "GIF89a not a png");
  Expected<Image> junk = read_png(tmp / "junk.png");
  ASSERT_FALSE(junk.ok());
  EXPECT_EQ(junk.status().code(), ErrorCode::kBadSignature);
  EXPECT_NE(junk.status().message().find("junk.png"), std::string::npos);

  Image img(8, 8);
  ASSERT_TRUE(write_png(tmp / "ok.png", img).ok());
  const std::string full = cbrdf::testing::read_text(tmp / "ok.png");
  write_bytes(tmp / "cut.png", full.substr(0, 40));
  Expected<Image> cut = read_png(tmp / "cut.png");
  ASSERT_FALSE(cut.ok());
  EXPECT_EQ(cut.status().code(), ErrorCode::kCorrupt);
  EXPECT_EQ(write_png(tmp / "e.png", Image()).code(), ErrorCode::kInvalidArgument);
}

// A table with a distinct value per bin and channel, and a few bins not measured.
BrdfTable patterned_table() {
  BrdfTable t;
  for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
    const BinIndex b = merl_bin(i);
    for (int c = 0; c < kChannels; ++c) {
      t.set_physical(c, i, 0.001 * (b.theta_h + 1) + 0.1 * b.theta_d + 7.0 * b.phi_d + 1000.0 * c);
    }
    if (bin_below_horizon(b.theta_h, b.theta_d, b.phi_d)) t.set_not_measured(i);
  }
  return t;
}

TEST(ExrTable, LayoutIsAsDocumented) {
  TempDir tmp;
  const BrdfTable t = patterned_table();
  ASSERT_TRUE(write_exr_table(tmp / "t.exr", t).ok());
  Expected<Image> img = read_exr(tmp / "t.exr");
  ASSERT_TRUE(img.ok()) << img.status().message();
  ASSERT_EQ(img->width, 1800);
  ASSERT_EQ(img->height, 810);
  // Bin (theta_h 17, theta_d 43, phi_d 101): tile (3, 4), pixel (3 * 180 + 101, 4 * 90 + 17).
  const MosaicPixel p = exr_table_pixel(17, 43, 101);
  EXPECT_EQ(p.x, 641);
  EXPECT_EQ(p.y, 377);
  const std::size_t idx = merl_index(17, 43, 101);
  ASSERT_TRUE(t.measured(0, idx));
  for (int c = 0; c < 3; ++c) EXPECT_EQ(img->at(641, 377, c), float(t.physical(c, idx))) << c;
  // A not-measured bin is 0 in RGB.
  std::size_t hidden = kBinsPerChannel;
  for (std::size_t i = 0; i < kBinsPerChannel && hidden == kBinsPerChannel; ++i) {
    if (!t.measured(0, i)) hidden = i;
  }
  ASSERT_LT(hidden, kBinsPerChannel);
  const BinIndex b = merl_bin(hidden);
  const MosaicPixel q = exr_table_pixel(b.theta_h, b.theta_d, b.phi_d);
  EXPECT_EQ(img->at(q.x, q.y, 0), 0.0f);
  // Last bin sits in the bottom-right corner.
  EXPECT_EQ(exr_table_pixel(89, 89, 179).x, 1799);
  EXPECT_EQ(exr_table_pixel(89, 89, 179).y, 809);
}

TEST(ExrTable, ReadsBackValuesAndMask) {
  TempDir tmp;
  const BrdfTable t = patterned_table();
  ASSERT_TRUE(write_exr_table(tmp / "t.exr", t).ok());
  Expected<BrdfTable> back = read_exr_table(tmp / "t.exr");
  ASSERT_TRUE(back.ok()) << back.status().message();
  std::size_t checked = 0;
  for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
    for (int c = 0; c < kChannels; ++c) {
      ASSERT_EQ(back->measured(c, i), t.measured(c, i)) << i;
      if (!t.measured(c, i)) continue;
      // float32 storage: the value read back is the float nearest the physical value.
      ASSERT_EQ(float(back->physical(c, i)), float(t.physical(c, i))) << i;
      ++checked;
    }
  }
  EXPECT_EQ(checked, 3 * kBinsPerChannel - t.count_not_measured());

  // An ordinary RGB image is not a table mosaic.
  ASSERT_TRUE(write_exr(tmp / "plain.exr", Image(1800, 810)).ok());
  Expected<BrdfTable> plain = read_exr_table(tmp / "plain.exr");
  ASSERT_FALSE(plain.ok());
  EXPECT_EQ(plain.status().code(), ErrorCode::kBadSignature);
  EXPECT_NE(plain.status().message().find("cbrdf.layout"), std::string::npos);
}

}  // namespace
}  // namespace cbrdf
