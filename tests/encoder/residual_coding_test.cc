// SPDX-License-Identifier: MIT
// RESD's range-coded codes (spec/container.md 4.6, "Range-coded codes", version 1.3): codes of
// every size round trip, the writer takes them in 1.3 files where they are smaller and never in
// 1.2 files, and malformed streams are refused with their error codes.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>

#include "bitstream/chunk_writers.h"
#include "bitstream/residual_codes.h"
#include "bitstream/residual_codes_writer.h"
#include "bitstream/residual_levels_writer.h"
#include "cbrdf/codec.h"
#include "cbrdf/container.h"
#include "cbrdf/container_writer.h"
#include "coding_1_2.h"
#include "refused.h"
#include "synthetic_model.h"

namespace cbrdf {
namespace {

using Bytes = std::vector<std::uint8_t>;

// Mode 3 as the reference writer uses it (L = 3, m = 8, a step per row): the codes of a target
// with smooth structure along every axis, channels alike but not equal, and noise, so that every
// context class and codes from 0 to hundreds occur. Two escapes.
Model interpolated_model() {
  Model m = testing::make_model(testing::six_slices(), true, 7);
  Residual& r = m.residual;
  r.max_error = 0.002;
  r.step = 2 * 0.002 * (1 - 1.0 / 1048576);
  r.knee = 1e-4;
  r.levels = 3;
  r.fine_multiplier = 8;
  r.row_shift.assign(kResidualRows, 0);
  for (std::size_t row = 0; row < kResidualRows; ++row) r.row_shift[row] = std::uint8_t(row % 3);
  std::vector<double> target(kMaskBits, std::numeric_limits<double>::quiet_NaN());
  std::uint32_t lcg = 12345;
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (m.not_measured.test(c, i)) continue;
      lcg = lcg * 1664525u + 1013904223u;
      const double noise = (double(lcg >> 8) / double(1 << 24) - 0.5) * 0.02;
      const double h = double(i / 16200), d = double((i / 180) % 90), p = double(i % 180);
      target[std::size_t(c) * kBinsPerChannel + i] =
          0.8 * std::sin(0.05 * h + 0.03 * d * (1 + 0.1 * c)) * std::cos(0.02 * p) +
          (h > 60 ? noise * 20 : noise);
    }
  }
  internal::quantize_interpolated(target.data(), &r);
  std::size_t measured = 0;
  while (m.not_measured.test(0, measured)) ++measured;
  r.escapes = {{std::uint32_t(measured), 0.25},
               {std::uint32_t(2 * kBinsPerChannel + measured + 180), 3.0}};
  return m;
}

Bytes encode_as(const Model& m, ContainerSettings::Format format) {
  ContainerSettings s = testing::coding_1_2();
  s.bits = 10;
  s.format = format;
  Expected<Bytes> e = encode_model(m, s);
  EXPECT_TRUE(e.ok()) << e.status().message();
  return e.ok() ? *e : Bytes{};
}

const Model& model13() {
  static const Model m = interpolated_model();
  return m;
}
const Bytes& file13() {
  static const Bytes b = encode_as(model13(), ContainerSettings::Format::kV13);
  return b;
}

Bytes resd_payload(const Bytes& file) {
  Expected<ParsedContainer> pc = parse_container(file);
  EXPECT_TRUE(pc.ok());
  const int k = pc->find(kTagResidual);
  EXPECT_GE(k, 0);
  return pc->payloads[std::size_t(k)];
}

std::uint32_t stored_bytes(const Bytes& file, std::string_view tag) {
  Expected<ParsedContainer> pc = parse_container(file);
  EXPECT_TRUE(pc.ok());
  return pc->layout.chunks[std::size_t(pc->find(tag))].stored_bytes;
}

// Mode 3's fields before the stream: 32 header bytes, 8100 row shifts, levels and multiplier,
// then predictor 3's coefficients (L = 3: 4 groups, 1 for R and 3 for G and B, 2 bytes each).
constexpr std::size_t kCoefficientsAt = 32 + kResidualRows + 2;
constexpr std::size_t kCoefficientBytes = 4 * (1 + 3 + 3) * 2;
constexpr std::size_t kLengthAt = kCoefficientsAt + kCoefficientBytes;
constexpr std::size_t kStreamAt = kLengthAt + 4;

std::uint32_t get_u32(const Bytes& b, std::size_t at) {
  return std::uint32_t(b[at]) | std::uint32_t(b[at + 1]) << 8 | std::uint32_t(b[at + 2]) << 16 |
         std::uint32_t(b[at + 3]) << 24;
}
void put_u32(Bytes* b, std::size_t at, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) (*b)[at + std::size_t(k)] = std::uint8_t(v >> (8 * k));
}

TEST(ResidualCoding, CodesOfEverySizeRoundTrip) {
  Model m = testing::make_model({0, 90}, false, 1);
  std::vector<std::int32_t> q(kMaskBits, 0);
  std::uint32_t lcg = 99;
  for (std::size_t b = 0; b < kMaskBits; b += 37) {
    if (m.not_measured.test(int(b / kBinsPerChannel), b % kBinsPerChannel)) continue;
    lcg = lcg * 1664525u + 1013904223u;
    const int bits = int(lcg >> 27);  // 0..31: magnitudes up to 2^28 below
    const std::int32_t v = std::int32_t((lcg >> 3) & ((1u << std::min(bits, 28)) - 1));
    q[b] = (lcg & 1) ? -v : v;
  }
  const std::int32_t top = std::int32_t(kMaxResidualCode);
  for (std::size_t b : {std::size_t(5), kBinsPerChannel + 7, 2 * kBinsPerChannel + 16200 * 89}) {
    ASSERT_FALSE(m.not_measured.test(int(b / kBinsPerChannel), b % kBinsPerChannel));
  }
  q[5] = top;
  q[kBinsPerChannel + 7] = -top;
  q[2 * kBinsPerChannel + 16200 * 89] = 1;
  const Bytes coded = internal::encode_residual_codes(q.data(), m.not_measured);
  std::vector<std::int32_t> back(kMaskBits, 0);
  Status s = internal::decode_residual_codes(coded, 0, m.not_measured, back.data());
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(back, q);
}

// Beyond the format's range: 2^28 + 1 (29 bits) is refused after decoding, 2^29 at its exponent.
TEST(ResidualCoding, OutOfRangeCodesAreRefused) {
  Model m = testing::make_model({0, 90}, false, 1);
  for (std::int32_t bad : {std::int32_t(kMaxResidualCode) + 1, -(std::int32_t(1) << 29)}) {
    std::vector<std::int32_t> q(kMaskBits, 0);
    q[3] = 4;
    q[kBinsPerChannel + 9] = bad;
    const Bytes coded = internal::encode_residual_codes(q.data(), m.not_measured);
    std::vector<std::int32_t> back(kMaskBits, 0);
    Status s = internal::decode_residual_codes(coded, 100, m.not_measured, back.data());
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.code(), ErrorCode::kCorrupt) << s.message();
    EXPECT_NE(s.message().find("channel G bin 9"), std::string::npos) << s.message();
    EXPECT_NE(s.message().find(bad > 0 ? "outside -2^28..2^28" : "exponent above 28"),
              std::string::npos)
        << s.message();
  }
}

// The writer: range-coded codes in the 1.3 file (smaller than the 1.2 coding; here, with
// channels alike, after prediction), the 1.2 coding in the 1.2 file, both decoding to the same
// codes and escapes.
TEST(ResidualCoding, WriterRangeCodesOnlyIn13Files) {
  const Bytes v12 = encode_as(model13(), ContainerSettings::Format::kV12);
  const Bytes p13 = resd_payload(file13()), p12 = resd_payload(v12);
  EXPECT_EQ(file13()[10], 3);
  EXPECT_EQ(v12[10], 2);
  EXPECT_EQ(p13[0], kResidualModeInterp);
  EXPECT_EQ(p13[1], kResidualPredictorRangePredicted);
  EXPECT_LE(p12[1], kResidualPredictorPhi);
  // 1.2 as before this coding existed: the payload of the varint writer.
  EXPECT_EQ(p12, encode_residual_chunk(model13(), false));
  EXPECT_LT(stored_bytes(file13(), kTagResidual), stored_bytes(v12, kTagResidual));
  // inspect_container reports the coding (`cbrdf info`'s "codes:" line).
  Expected<ContainerInfo> i13 = inspect_container(file13()), i12 = inspect_container(v12);
  ASSERT_TRUE(i13.ok() && i12.ok());
  EXPECT_EQ(i13->residual_coding, kResidualPredictorRangePredicted);
  EXPECT_EQ(i12->residual_coding, p12[1]);
  for (const Bytes* f : {&file13(), &v12}) {
    Expected<Model> got = decode_model(*f);
    ASSERT_TRUE(got.ok()) << got.status().message();
    EXPECT_EQ(got->residual.codes, model13().residual.codes);
    ASSERT_EQ(got->residual.escapes.size(), 2u);
    EXPECT_EQ(got->residual.escapes[1].bin, model13().residual.escapes[1].bin);
    EXPECT_EQ(got->residual.escapes[1].stored, 3.0);
    EXPECT_EQ(got->residual.values, model13().residual.values);
  }
}

// The writer takes whichever coding is smaller once stored: here codes all zero but one, where
// zstd's runs cost about what one adaptive bit per bin does, either may win.
TEST(ResidualCoding, WriterTakesTheSmallerCoding) {
  Model m = testing::make_model(testing::six_slices(), true, 7);
  m.residual.max_error = 0.01;
  m.residual.step = 0.0199;
  m.residual.knee = 1e-4;
  m.residual.codes.assign(kMaskBits, 0);
  m.residual.codes[kBinsPerChannel / 2] = 3;
  const Bytes f = encode_as(m, ContainerSettings::Format::kV13);
  const Bytes varints = encode_residual_chunk(m, false);
  const Bytes chosen = resd_payload(f);
  auto stored = [](const Bytes& payload) {
    std::vector<ChunkToWrite> one = {{std::string(kTagResidual), payload, true}};
    Expected<Bytes> out = write_container(one, 19, 3);
    EXPECT_TRUE(out.ok());
    return out.ok() ? out->size() : 0;
  };
  const std::size_t varint_bytes = stored(varints);
  const std::size_t chosen_bytes = stored(chosen);
  EXPECT_LE(chosen_bytes, varint_bytes);
  if (chosen[1] == kResidualPredictorRange) {
    EXPECT_LT(chosen_bytes, varint_bytes);
  } else {
    EXPECT_EQ(chosen, varints);
  }
  Expected<Model> got = decode_model(f);
  ASSERT_TRUE(got.ok()) << got.status().message();
  EXPECT_EQ(got->residual.codes, m.residual.codes);
  Expected<ContainerInfo> info = inspect_container(f);
  ASSERT_TRUE(info.ok());
  EXPECT_EQ(info->residual_coding, chosen[1]);
}

// Rewrites RESD's payload of the 1.3 file (checksums valid), at the given minor version.
Bytes with_resd(const std::function<void(Bytes*)>& edit, int minor = 3) {
  Expected<ParsedContainer> pc = parse_container(file13());
  EXPECT_TRUE(pc.ok());
  std::vector<ChunkToWrite> chunks;
  for (std::size_t k = 0; k + 1 < pc->layout.chunks.size(); ++k) {
    chunks.push_back({pc->layout.chunks[k].tag, pc->payloads[k], true});
    if (chunks.back().tag == kTagResidual) edit(&chunks.back().payload);
  }
  Expected<Bytes> out = write_container(chunks, 3, 3);
  EXPECT_TRUE(out.ok()) << out.status().message();
  Bytes b = out.ok() ? *out : Bytes{};
  b[10] = std::uint8_t(minor);
  return b;
}

// A damaged RESD: the message names the chunk.
void expect_error(const Bytes& b, ErrorCode code, const std::string& needle) {
  testing::expect_refused(b, code, needle, "RESD");
}

TEST(ResidualCoding, MalformedStreamsAreRefused) {
  ASSERT_TRUE(decode_model(with_resd([](Bytes*) {})).ok());
  ASSERT_EQ(resd_payload(file13())[1], kResidualPredictorRangePredicted);
  const std::uint32_t length = get_u32(resd_payload(file13()), kLengthAt);
  ASSERT_GT(length, 100u);
  // Only a 1.3 file may hold range-coded codes (a 1.2 reader knows predictors 0 and 1).
  {
    // (A 1.2 file cannot hold BASE either, so the payload is read as in a 1.2 file directly.)
    for (std::uint8_t predictor : {kResidualPredictorRange, kResidualPredictorRangePredicted}) {
      Bytes p = resd_payload(file13());
      p[1] = predictor;
      Residual r;
      Status s = decode_residual_chunk(p, 2, model13().not_measured, &r);
      EXPECT_EQ(s.code(), ErrorCode::kCorrupt) << s.message();
      EXPECT_NE(s.message().find("predictor " + std::to_string(predictor)), std::string::npos)
          << s.message();
    }
  }
  expect_error(with_resd([](Bytes* p) { (*p)[1] = 4; }), ErrorCode::kCorrupt, "predictor 4");
  // The payload ends inside the coefficients.
  expect_error(with_resd([](Bytes* p) { p->resize(kCoefficientsAt + 5); }), ErrorCode::kTruncated,
               "a prediction coefficient");
  // G's finest-level coefficient for the previous slab at its largest (about 128): codes grow
  // by that factor slab after slab until one leaves the format's range.
  expect_error(with_resd([](Bytes* p) {
                 const std::size_t g_level0_a = kCoefficientsAt + 4 * 2;
                 (*p)[g_level0_a] = 0xFF;
                 (*p)[g_level0_a + 1] = 0x7F;
               }),
               ErrorCode::kCorrupt, "predicted code of channel G");
  // The payload ends inside the stream, or inside the length field.
  expect_error(with_resd([](Bytes* p) { p->resize(kStreamAt + 50); }), ErrorCode::kTruncated,
               "coded stream");
  expect_error(with_resd([](Bytes* p) { p->resize(kLengthAt + 2); }), ErrorCode::kTruncated,
               "coded stream length");
  // The stream is cut short (its length says so): the decoder runs past its end.
  expect_error(with_resd([&](Bytes* p) {
                 p->erase(p->begin() + std::ptrdiff_t(kStreamAt + length / 2),
                          p->begin() + std::ptrdiff_t(kStreamAt + length));
                 put_u32(p, kLengthAt, length - (length - length / 2));
               }),
               ErrorCode::kTruncated, "before its last value");
  // Bytes inside the stream's length after its last value.
  expect_error(with_resd([&](Bytes* p) {
                 p->insert(p->begin() + std::ptrdiff_t(kStreamAt + length), 3, 0x55);
                 put_u32(p, kLengthAt, length + 3);
               }),
               ErrorCode::kCorrupt, "3 bytes after the coded stream's last value");
  // Bytes after the escapes.
  expect_error(with_resd([](Bytes* p) { p->push_back(0); }), ErrorCode::kCorrupt,
               "1 unexpected bytes");
  // A damaged stream decodes to something else: refused, never accepted silently.
  Expected<Model> damaged = decode_model(with_resd([](Bytes* p) { (*p)[kStreamAt + 40] ^= 0x10; }));
  EXPECT_TRUE(!damaged.ok() || damaged->residual.codes != model13().residual.codes);
}

}  // namespace
}  // namespace cbrdf
