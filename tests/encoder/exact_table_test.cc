// SPDX-License-Identifier: MIT
// The exact table coding (codec/decoder/src/bitstream/exact_table.h, its writer
// codec/encoder/src/bitstream/exact_table_writer.h): bit-exact round trips of
// every kind of IEEE pattern, and refusal of malformed payloads with kCorrupt and a message naming
// the problem.
#include "bitstream/exact_table.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>

#include "bitstream/exact_table_writer.h"
#include "byte_writer.h"
#include "heap_meter.h"

namespace cbrdf {
namespace {

using internal::decode_exact_table;
using internal::encode_exact_table;

constexpr int kRows = kThetaHBins * kThetaDBins;
constexpr int kContexts = 8;  // symbol streams per channel (spec)

std::uint64_t bits_of(double v) {
  return std::bit_cast<std::uint64_t>(v);
}
double from_bits(std::uint64_t b) {
  return std::bit_cast<double>(b);
}

// A smooth, positive table with the horizon not measured (-1), like a real material.
BrdfTable smooth_table() {
  BrdfTable t;
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      const BinIndex b = merl_bin(i);
      const double th = b.theta_h / 90.0, td = b.theta_d / 90.0, pd = b.phi_d / 180.0;
      t.set_stored(c, i, (1.0 + c) * std::exp(-8.0 * th * th) + 0.3 * td + 0.1 * pd * pd);
      if (b.theta_d > 60 && b.phi_d > 60 && b.phi_d < 120) t.set_stored(c, i, -1.0);
    }
  }
  return t;
}

void expect_bit_identical(const BrdfTable& a, const BrdfTable& b) {
  const auto& x = a.stored_values();
  const auto& y = b.stored_values();
  ASSERT_EQ(x.size(), y.size());
  std::size_t first_diff = x.size();
  for (std::size_t i = 0; i < x.size() && first_diff == x.size(); ++i)
    if (bits_of(x[i]) != bits_of(y[i])) first_diff = i;
  EXPECT_EQ(first_diff, x.size()) << "first differing value at " << first_diff << ": " << std::hex
                                  << bits_of(x[first_diff]) << " vs " << bits_of(y[first_diff]);
}

void expect_round_trip(const BrdfTable& t) {
  const std::vector<std::uint8_t> bytes = encode_exact_table(t, 3);
  auto back = decode_exact_table(bytes);
  ASSERT_TRUE(back.ok()) << back.status().message();
  expect_bit_identical(t, *back);
}

TEST(ExactTable, SmoothTableRoundTripsAndCompresses) {
  const BrdfTable t = smooth_table();
  const std::vector<std::uint8_t> bytes = encode_exact_table(t, 3);
  auto back = decode_exact_table(bytes);
  ASSERT_TRUE(back.ok()) << back.status().message();
  expect_bit_identical(t, *back);
  // Smooth data: the predictors leave far fewer than 64 bits per value.
  EXPECT_LT(bytes.size(), t.stored_values().size() * 8 / 3);
}

TEST(ExactTable, SpecialPatternsRoundTrip) {
  BrdfTable t = smooth_table();
  const double inf = std::numeric_limits<double>::infinity();
  const std::uint64_t specials[] = {bits_of(-0.0),
                                    bits_of(0.0),
                                    bits_of(-inf),
                                    bits_of(inf),
                                    0x7FF8000000000001ull,
                                    0xFFF0000000000123ull,  // NaN payloads
                                    0x7FF4000000000000ull,
                                    0x0000000000000001ull,
                                    0x800FFFFFFFFFFFFFull,  // denormals
                                    bits_of(std::numeric_limits<double>::max()),
                                    bits_of(-1.0),
                                    bits_of(-1e300),
                                    0xFFFFFFFFFFFFFFFFull,
                                    0x7FFFFFFFFFFFFFFFull};
  std::size_t n = 0;
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; i += 977) {
      t.set_stored(c, i, from_bits(specials[n++ % std::size(specials)]));
    }
  }
  // The first and last bins of every channel and a whole row, where the predictors start.
  for (int c = 0; c < kChannels; ++c) {
    t.set_stored(c, 0, from_bits(0x7FF8DEADBEEF0001ull));
    t.set_stored(c, kBinsPerChannel - 1, -0.0);
    for (int k = 0; k < kPhiDBins; ++k) t.set_stored(c, merl_index(5, 7, k), -inf);
  }
  expect_round_trip(t);
}

TEST(ExactTable, RandomBitsRoundTrip) {
  BrdfTable t;
  std::mt19937_64 rng(18);
  for (double& v : t.stored_values()) v = from_bits(rng());
  expect_round_trip(t);
}

TEST(ExactTable, AllNotMeasuredAndAllZeroRoundTrip) {
  BrdfTable zero;
  expect_round_trip(zero);
  BrdfTable none;
  for (double& v : none.stored_values()) v = -1.0;
  expect_round_trip(none);
}

// ---- malformed payloads, written by hand in the layout of the spec ---------------------------

void stream(ByteWriter* w, const std::vector<std::uint8_t>& content) {
  w->u8(0);  // stored as is
  w->u32(std::uint32_t(content.size()));
  w->u32(std::uint32_t(content.size()));
  w->bytes(content);
}

// An all-zero table: no exceptions, predictor 0 everywhere, every residual 0 (symbol 0, context
// 0). `edit` changes the parts before they are written.
struct Parts {
  std::uint8_t method = 1;
  std::uint32_t count = 0;
  std::vector<std::uint8_t> bitmap = std::vector<std::uint8_t>(kChannels * kBinsPerChannel / 8);
  std::vector<std::uint8_t> values;
  std::vector<std::uint8_t> choices = std::vector<std::uint8_t>(kChannels * kRows);
  std::vector<std::uint8_t> symbols0 = std::vector<std::uint8_t>(kBinsPerChannel);
  std::vector<std::uint8_t> bits;
  std::vector<std::uint8_t> trailer;
};

std::vector<std::uint8_t> write(const Parts& p) {
  ByteWriter w;
  w.u8(p.method);
  w.u32(p.count);
  stream(&w, p.bitmap);
  stream(&w, p.values);
  stream(&w, p.choices);
  for (int c = 0; c < kChannels; ++c) {
    stream(&w, c == 0 ? p.symbols0 : std::vector<std::uint8_t>(kBinsPerChannel));
    for (int ctx = 1; ctx < kContexts; ++ctx) stream(&w, {});
    stream(&w, c == 0 ? p.bits : std::vector<std::uint8_t>{});
  }
  w.bytes(p.trailer);
  return w.take();
}

void expect_corrupt(const std::vector<std::uint8_t>& bytes, const std::string& words) {
  auto t = decode_exact_table(bytes);
  ASSERT_FALSE(t.ok()) << "accepted; expected: " << words;
  EXPECT_EQ(t.status().code(), ErrorCode::kCorrupt) << t.status().message();
  EXPECT_NE(t.status().message().find(words), std::string::npos) << t.status().message();
}

TEST(ExactTableMalformed, HandWrittenReferenceDecodes) {
  auto t = decode_exact_table(write(Parts{}));
  ASSERT_TRUE(t.ok()) << t.status().message();
  expect_bit_identical(*t, BrdfTable());
}

TEST(ExactTableMalformed, HeaderFieldsAreChecked) {
  Parts p;
  p.method = 2;
  expect_corrupt(write(p), "unknown method 2");
  p = Parts{};
  p.count = 5;
  expect_corrupt(write(p), "bitmap marks 0 bins but the header declares 5");
  p = Parts{};
  p.count = 1;
  p.bitmap[0] = 1;
  expect_corrupt(write(p), "exception values: declares 0 bytes where 8 are possible");
  p.bitmap[0] = 0;
  p.values = {0, 0, 0, 0, 0, 0, 0xF0, 0xBF};  // -1.0, but no bit set in the bitmap
  expect_corrupt(write(p), "bitmap marks 0 bins but the header declares 1");
  p.bitmap[0] = 1;
  p.values[7] = 0x3F;  // +1.0: not a not-measured value
  expect_corrupt(write(p), "lacks the sign bit");
  p = Parts{};
  p.choices[123] = 16;
  expect_corrupt(write(p), "predictor 16 of row 123");
}

TEST(ExactTableMalformed, StreamContentsAreChecked) {
  Parts p;
  p.symbols0.pop_back();
  expect_corrupt(write(p), "symbol stream 0 ends early");
  p = Parts{};
  p.symbols0[1000] = 200;
  expect_corrupt(write(p), "symbol 200 is above 127");
  p = Parts{};
  p.symbols0[1000] = 127;  // a 64-bit residual whose 62 low bits are missing
  expect_corrupt(write(p), "low-bit stream ends early");
  p = Parts{};
  p.bits = {0};
  expect_corrupt(write(p), "holds more bits than the channel uses");
  p = Parts{};
  p.symbols0[0] = 127;  // an odd 64-bit zigzag value: a negative residual from prediction 0
  p.bits = std::vector<std::uint8_t>(8, 0);
  p.bits[0] = 1;
  expect_corrupt(write(p), "sign bit set");
  p = Parts{};
  p.trailer = {1, 2, 3};
  expect_corrupt(write(p), "3 bytes follow the last stream");
}

TEST(ExactTableMalformed, TruncationAndHostileSizesAreRefusedWithoutLargeAllocations) {
  const std::vector<std::uint8_t> good = encode_exact_table(smooth_table(), 3);
  for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{5}, std::size_t{14},
                        good.size() / 2, good.size() - 1}) {
    auto t = decode_exact_table(std::span(good).first(n));
    ASSERT_FALSE(t.ok()) << n;
    EXPECT_EQ(t.status().code(), ErrorCode::kCorrupt) << n << ": " << t.status().message();
  }
  // A symbol stream declaring 4 GiB of content after the shared streams.
  std::vector<std::uint8_t> hostile = write(Parts{});
  const std::size_t first_symbols =
      1 + 4 + (9 + kChannels * kBinsPerChannel / 8) + 9 + (9 + kChannels * kRows);
  ASSERT_EQ(hostile[first_symbols], 0);
  for (int b = 1; b < 9; ++b) hostile[first_symbols + std::size_t(b)] = 0xFF;
  testing::heap::Meter meter;
  meter.start();
  expect_corrupt(hostile, "declares 4294967295 bytes where at most 1458000 are possible");
  EXPECT_LT(meter.largest_bytes(), std::size_t{16} << 20);
}

}  // namespace
}  // namespace cbrdf
