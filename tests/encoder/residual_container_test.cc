// SPDX-License-Identifier: MIT
// 'RESD' payloads (spec/container.md 4.6) as a reader meets them: a model with a residual round
// trips exactly, and every malformed payload is refused with its error code and a message that
// names the chunk.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <functional>

#include "bitstream/residual_levels.h"
#include "byte_writer.h"
#include "cbrdf/codec.h"
#include "cbrdf/container.h"
#include "cbrdf/container_writer.h"
#include "coding_1_2.h"
#include "refused.h"
#include "synthetic_model.h"

namespace cbrdf {
namespace {

using Bytes = std::vector<std::uint8_t>;

// A model of six slices with the standard mask and a residual: sparse codes of both signs, a
// band of larger ones and two escapes.
Model residual_model() {
  Model m = testing::make_model(testing::six_slices(), true, 11);
  Residual& r = m.residual;
  r.max_error = 0.01;
  r.step = 0.0199;
  r.knee = 0.5;
  r.codes.assign(std::size_t(kChannels) * kBinsPerChannel, 0);
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (m.not_measured.test(c, i)) continue;
      std::int32_t q = 0;
      if (i % 101 == 7) q = std::int32_t(i % 9) - 4;
      if (i / 16200 == 3) q = std::int32_t((i / 180) % 40) - 20 + c;  // theta_h bin 3
      r.codes[std::size_t(c) * kBinsPerChannel + i] = q;
    }
  }
  std::size_t measured = 0;
  while (m.not_measured.test(0, measured)) ++measured;
  r.escapes = {{std::uint32_t(measured), 0.25},
               {std::uint32_t(kBinsPerChannel + measured + 180), 3.0}};
  return m;
}

// The file of a test model, 8 bits, zstd level 3.
Bytes encode_for_test(const Model& m) {
  ContainerSettings s = testing::coding_1_2();
  s.bits = 8;
  s.zstd_level = 3;
  Expected<Bytes> e = encode_model(m, s);
  EXPECT_TRUE(e.ok()) << e.status().message();
  return e.ok() ? *e : Bytes{};
}

const Bytes& residual_file() {
  static const Bytes b = encode_for_test(residual_model());
  return b;
}

TEST(ResidualContainer, RoundTripsExactly) {
  const Model want = residual_model();
  Expected<Model> got = decode_model(residual_file());
  ASSERT_TRUE(got.ok()) << got.status().message();
  EXPECT_EQ(got->residual.max_error, want.residual.max_error);
  EXPECT_EQ(got->residual.step, want.residual.step);
  EXPECT_EQ(got->residual.codes, want.residual.codes);
  ASSERT_EQ(got->residual.escapes.size(), 2u);
  EXPECT_EQ(got->residual.escapes[1].bin, want.residual.escapes[1].bin);
  EXPECT_EQ(got->residual.escapes[1].stored, 3.0);
  // The table: the escapes exactly, other measured bins by the normative formula.
  Model base = *got;
  base.residual = Residual{};
  const BrdfTable with = got->table(), without = base.table();
  EXPECT_EQ(with.stored_values()[want.residual.escapes[0].bin], 0.25);
  const std::size_t i = 3 * 16200 + 90 * 180 / 2 + 77;  // inside the band of larger codes
  ASSERT_FALSE(got->not_measured.test(1, i));
  EXPECT_EQ(got->residual.knee, 0.5);
  const double y = std::log1p(without.stored(1, i) / 0.5) +
                   double(want.residual.codes[kBinsPerChannel + i]) * want.residual.step;
  EXPECT_EQ(with.stored(1, i), y > 0 ? std::expm1(y) * 0.5 : 0.0);
  EXPECT_EQ(residual_file()[10], 2);
}

// Mode 1 (lossless): the table comes back bit for bit, whatever the model says, and a table whose
// not-measured bins differ from MASK is refused by the encoder.
TEST(ResidualContainer, ExactTableRoundTripsBitForBit) {
  Model m = testing::make_model({0, 45, 90}, false, 3);
  testing::set_standard_mask(&m);
  BrdfTable exact = m.table();
  double* v = exact.stored_values().data();
  for (std::size_t b = 0; b < exact.stored_values().size(); b += 7) {
    if (v[b] >= 0.0) v[b] = v[b] * 1.001 + 1e-9 * double(b % 13);  // not the model's value
  }
  m.residual.exact = std::make_shared<const BrdfTable>(exact);
  ContainerSettings s = testing::coding_1_2();
  s.zstd_level = 3;
  Expected<Bytes> bytes = encode_model(m, s);
  ASSERT_TRUE(bytes.ok()) << bytes.status().message();
  EXPECT_EQ((*bytes)[10], 2);
  Expected<BrdfTable> t = decode_table(*bytes);
  ASSERT_TRUE(t.ok()) << t.status().message();
  EXPECT_EQ(std::memcmp(t->stored_values().data(), exact.stored_values().data(),
                        exact.stored_values().size() * sizeof(double)),
            0);
  Expected<ContainerInfo> info = inspect_container(*bytes);
  ASSERT_TRUE(info.ok());
  EXPECT_EQ(info->residual_mode, 1);
  BrdfTable wrong = exact;
  wrong.stored_values()[0] = -1.0;  // bin 0 is measured in MASK
  m.residual.exact = std::make_shared<const BrdfTable>(wrong);
  Expected<Bytes> refused = encode_model(m, s);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), ErrorCode::kInvalidArgument);
}

// Rewrites the file with RESD's payload edited (checksums valid) and the given minor version.
Bytes with_resd(const std::function<void(Bytes*)>& edit, int minor = 2, bool twice = false,
                const Bytes& source = residual_file()) {
  Expected<ParsedContainer> pc = parse_container(source);
  EXPECT_TRUE(pc.ok());
  std::vector<ChunkToWrite> chunks;
  for (std::size_t k = 0; k + 1 < pc->layout.chunks.size(); ++k) {
    chunks.push_back({pc->layout.chunks[k].tag, pc->payloads[k], true});
    if (chunks.back().tag == kTagResidual) {
      edit(&chunks.back().payload);
      if (twice) chunks.push_back(chunks.back());
    }
  }
  // Minor 3 has a framing of its own (spec 2.2): written as such, not patched.
  Expected<Bytes> out = write_container(chunks, 3, minor >= 3 ? std::uint16_t(minor) : 0);
  EXPECT_TRUE(out.ok()) << out.status().message();
  Bytes b = out.ok() ? *out : Bytes{};
  if (minor < 3) b[10] = std::uint8_t(minor);
  return b;
}

// A damaged RESD: the message names the chunk.
void expect_error(const Bytes& b, ErrorCode code, const std::string& needle) {
  testing::expect_refused(b, code, needle, "RESD");
}

void put_f64(Bytes* b, std::size_t at, double v) {
  const std::uint64_t u = std::bit_cast<std::uint64_t>(v);
  for (int k = 0; k < 8; ++k) (*b)[at + std::size_t(k)] = std::uint8_t(u >> (8 * k));
}

TEST(ResidualContainer, MalformedPayloadsAreRefused) {
  expect_error(with_resd([](Bytes* p) { (*p)[0] = 5; }), ErrorCode::kUnsupported,
               "residual mode 5");
  // Mode 4 exists from version 1.3 on (the payload is mode 0's: refused before it is read).
  expect_error(with_resd([](Bytes* p) { (*p)[0] = 4; }), ErrorCode::kCorrupt,
               "residual mode 4 (a step per level) in a version 1.2 file");
  expect_error(with_resd([](Bytes* p) { (*p)[1] = 2; }), ErrorCode::kCorrupt, "predictor 2");
  expect_error(with_resd([](Bytes* p) { (*p)[2] = 1; }), ErrorCode::kCorrupt, "reserved 1");
  expect_error(with_resd([](Bytes* p) { put_f64(p, 4, std::nan("")); }), ErrorCode::kNumeric,
               "max error nan");
  expect_error(with_resd([](Bytes* p) { put_f64(p, 4, 1e-7); }), ErrorCode::kNumeric, "is outside");
  expect_error(with_resd([](Bytes* p) { put_f64(p, 12, 0.03); }), ErrorCode::kNumeric,
               "step 0.0299");
  expect_error(with_resd([](Bytes* p) { put_f64(p, 12, 0.0); }), ErrorCode::kNumeric, "step 0");
  expect_error(with_resd([](Bytes* p) { put_f64(p, 20, 0.0); }), ErrorCode::kNumeric, "knee 0");
  expect_error(with_resd([](Bytes* p) { put_f64(p, 20, 1e13); }), ErrorCode::kNumeric,
               "knee 10000000000000");
  expect_error(with_resd([](Bytes* p) { (*p)[30] = 1; }), ErrorCode::kLimit, "escape count");
  expect_error(with_resd([](Bytes* p) { p->resize(32 + 1000); }), ErrorCode::kTruncated,
               "before the last measured bin");
  // A code outside -2^28..2^28: the first varint replaced by a 5-byte value.
  expect_error(with_resd([](Bytes* p) {
                 const Bytes big = {0xFE, 0xFF, 0xFF, 0xFF, 0x0F};
                 p->erase(p->begin() + 32);
                 p->insert(p->begin() + 32, big.begin(), big.end());
               }),
               ErrorCode::kCorrupt, "outside -2^28..2^28");
  expect_error(with_resd([](Bytes* p) {
                 const Bytes overlong = {0x80, 0x00};
                 p->erase(p->begin() + 32);
                 p->insert(p->begin() + 32, overlong.begin(), overlong.end());
               }),
               ErrorCode::kCorrupt, "overlong");
  // The last escape's value (the payload's last 8 bytes) negative, then its bin moved past the
  // table (its gap is the varint before the value).
  expect_error(with_resd([](Bytes* p) { put_f64(p, p->size() - 8, -1.0); }), ErrorCode::kNumeric,
               "escape value -1");
  expect_error(with_resd([](Bytes* p) {
                 const Bytes far = {0xFF, 0xFF, 0xFF, 0xFF, 0x0F};
                 std::size_t at = p->size() - 9;
                 while ((*p)[at - 1] & 0x80) --at;  // the gap's first byte
                 p->erase(p->begin() + std::ptrdiff_t(at), p->end() - 8);
                 p->insert(p->begin() + std::ptrdiff_t(at), far.begin(), far.end());
               }),
               ErrorCode::kCorrupt, "past the table or not measured");
  expect_error(with_resd([](Bytes* p) { p->push_back(0); }), ErrorCode::kCorrupt,
               "unexpected bytes");
  expect_error(with_resd([](Bytes*) {}, 1), ErrorCode::kCorrupt, "needs container version 1.2");
  Expected<Model> dup = decode_model(with_resd([](Bytes*) {}, 2, true));
  ASSERT_FALSE(dup.ok());
  EXPECT_EQ(dup.status().code(), ErrorCode::kCorrupt);
  EXPECT_NE(dup.status().message().find("duplicate"), std::string::npos);
}

// Mode 2: the residual_model() with a step per row (shifts 0, 2 and 4 of the bound 0.01).
Model rows_model() {
  Model m = residual_model();
  m.residual.row_shift.resize(kThetaHBins * kThetaDBins);
  for (std::size_t r = 0; r < m.residual.row_shift.size(); ++r) {
    m.residual.row_shift[r] = std::uint8_t((r * 7 / 3) % 7);
  }
  return m;
}

const Bytes& rows_file() {
  static const Bytes b = encode_for_test(rows_model());
  return b;
}

TEST(ResidualContainer, RowStepsRoundTripExactly) {
  const Model want = rows_model();
  Expected<Model> got = decode_model(rows_file());
  ASSERT_TRUE(got.ok()) << got.status().message();
  EXPECT_EQ(got->residual.row_shift, want.residual.row_shift);
  EXPECT_EQ(got->residual.codes, want.residual.codes);
  EXPECT_EQ(got->residual.escapes.size(), 2u);
  Model base = *got;
  base.residual = Residual{};
  const BrdfTable with = got->table(), without = base.table();
  const std::size_t i = 3 * 16200 + 90 * 180 / 2 + 77;  // row 3 * 90 + 45: shift (315 * 7 / 3) % 7
  ASSERT_EQ(want.residual.row_shift[i / 180], 0);
  const std::size_t j = i + 180;  // the next row: shift 2
  ASSERT_EQ(want.residual.row_shift[j / 180], 2);
  for (std::size_t b : {i, j}) {
    ASSERT_FALSE(got->not_measured.test(1, b));
    const double step = std::ldexp(0.0199, want.residual.row_shift[b / 180]);
    const double y = std::log1p(without.stored(1, b) / 0.5) +
                     double(want.residual.codes[kBinsPerChannel + b]) * step;
    EXPECT_EQ(with.stored(1, b), y > 0 ? std::expm1(y) * 0.5 : 0.0) << b;
  }
  Expected<ContainerInfo> info = inspect_container(rows_file());
  ASSERT_TRUE(info.ok()) << info.status().message();
  EXPECT_EQ(info->residual_mode, 2);
  EXPECT_EQ(info->residual_max_error, 0.16);  // shifts 0, 2 and 4
  EXPECT_EQ(info->residual_min_error, 0.01);
  // The same codes without the row steps are a mode 0 file that decodes as before.
  Expected<Model> plain = decode_model(residual_file());
  ASSERT_TRUE(plain.ok());
  EXPECT_TRUE(plain->residual.row_shift.empty());
}

TEST(ResidualContainer, MalformedRowStepsAreRefused) {
  const Bytes& f = rows_file();
  expect_error(with_resd([](Bytes* p) { (*p)[32 + 17] = 25; }, 2, false, f), ErrorCode::kNumeric,
               "row shift 25 at payload offset 49");
  // 0.01 x 2^11 = 20.48 > 16.
  expect_error(with_resd([](Bytes* p) { (*p)[32 + 8099] = 11; }, 2, false, f), ErrorCode::kNumeric,
               "row shift 11");
  // A bound of 2 allows shifts up to 3.
  expect_error(with_resd([](Bytes* p) { put_f64(p, 4, 2.0); }, 2, false, f), ErrorCode::kNumeric,
               "row shift");
  expect_error(with_resd([](Bytes* p) { p->resize(32 + 8000); }, 2, false, f),
               ErrorCode::kTruncated, "row shifts");
  // A mode 0 payload read as mode 2 loses 8100 bytes of codes to the shifts: refused either way.
  Expected<Model> m = decode_model(with_resd([](Bytes* p) { (*p)[0] = 2; }));
  EXPECT_FALSE(m.ok());
  // And the writer refuses what no reader accepts.
  Model bad = rows_model();
  bad.residual.row_shift[5] = 12;
  ContainerSettings s = testing::coding_1_2();
  EXPECT_EQ(encode_model(bad, s).status().code(), ErrorCode::kInvalidArgument);
  bad.residual.row_shift.resize(100);
  EXPECT_EQ(encode_model(bad, s).status().code(), ErrorCode::kInvalidArgument);
}

// Mode 3: rows_model()'s codes correcting an interpolation over 2 levels, finest multiplier 3.
Model interp_model() {
  Model m = rows_model();
  // rows_model()'s codes, constant along phi_d, would add up along the coarsest level's chain
  // past the format's +-64 (spec 4.6): at most 4 in size, their sign alternating between nodes.
  for (std::size_t b = 0; b < kMaskBits; ++b) {
    const std::size_t i = b % kBinsPerChannel;
    const std::size_t d = i / kPhiDBins % kThetaDBins, p = i % kPhiDBins;
    std::int32_t& q = m.residual.codes[b];
    q = std::clamp(q, -4, 4) * ((d / 4 + p / 4) % 2 ? 1 : -1);
  }
  m.residual.levels = 2;
  m.residual.fine_multiplier = 3;
  internal::rebuild_interpolated(&m.residual);
  return m;
}

const Bytes& interp_file() {
  static const Bytes b = encode_for_test(interp_model());
  return b;
}

// The rebuild of one (channel, theta_h) slab written out from the pseudo-code of spec 4.6, mode
// 3, as a second implementation would: R(d, p) in binary64.
std::vector<double> spec_slab(const Residual& r, int c, int h) {
  std::vector<double> R(std::size_t(kThetaDBins) * kPhiDBins, 0.0);
  auto at = [&](int d, int p) -> double& { return R[std::size_t(d) * kPhiDBins + std::size_t(p)]; };
  // Level l's multiplier: m on the finest (0), m_l between (mode 4; 1 in mode 3), none at L.
  auto multiplier = [&](int l) {
    return l == 0          ? double(r.fine_multiplier)
           : l == r.levels ? 1.0
                           : double(r.middle_multipliers[std::size_t(l - 1)]);
  };
  auto set = [&](int d, int p, int l, double P) {
    const std::size_t i = merl_index(h, d, p);
    double step = std::ldexp(r.step, r.row_shift[i / kPhiDBins]);
    if (l < r.levels) step *= multiplier(l);
    at(d, p) = P + double(r.codes[std::size_t(c) * kBinsPerChannel + i]) * step;
  };
  const int S = 1 << r.levels;
  for (int d = 0; d < 90; d += S) {
    for (int p = 0; p < 180; p += S) set(d, p, r.levels, p > 0 ? at(d, p - S) : 0.0);
  }
  for (int hh = S / 2, l = r.levels - 1; hh >= 1; hh /= 2, --l) {
    for (int d = 0; d < 90; d += 2 * hh) {
      for (int p = hh; p < 180; p += 2 * hh) {
        set(d, p, l, 0.5 * (at(d, p - hh) + at(d, (p + hh) % 180)));
      }
    }
    for (int d = hh; d < 90; d += 2 * hh) {
      for (int p = 0; p < 180; p += hh) {
        set(d, p, l, d + hh < 90 ? 0.5 * (at(d - hh, p) + at(d + hh, p)) : at(d - hh, p));
      }
    }
  }
  return R;
}

// The decoder's R against spec_slab's in every channel, at theta_h 3 (a band of codes in every
// row) and 0 and 89 (only the sparse ones).
void expect_rebuilt_as_specified(const Residual& r) {
  for (int c = 0; c < kChannels; ++c) {
    for (int h : {0, 3, 89}) {
      const std::vector<double> R = spec_slab(r, c, h);
      const double* v = r.values.data() + std::size_t(c) * kBinsPerChannel + merl_index(h, 0, 0);
      EXPECT_EQ(std::memcmp(R.data(), v, R.size() * sizeof(double)), 0) << c << " " << h;
    }
  }
}

Bytes payload_of_resd(const Bytes& file) {
  Expected<ParsedContainer> pc = parse_container(file);
  EXPECT_TRUE(pc.ok() && pc->find(kTagResidual) >= 0);
  return pc.ok() && pc->find(kTagResidual) >= 0 ? pc->payloads[std::size_t(pc->find(kTagResidual))]
                                                : Bytes{0xFF};
}

TEST(ResidualContainer, InterpolatedLevelsRoundTripAndRebuildAsSpecified) {
  const Model want = interp_model();
  Expected<Model> got = decode_model(interp_file());
  ASSERT_TRUE(got.ok()) << got.status().message();
  EXPECT_EQ(payload_of_resd(interp_file())[0], 3);
  EXPECT_EQ(got->residual.levels, 2);
  EXPECT_EQ(got->residual.fine_multiplier, 3);
  EXPECT_EQ(got->residual.codes, want.residual.codes);
  EXPECT_EQ(got->residual.row_shift, want.residual.row_shift);
  ASSERT_EQ(got->residual.values.size(), want.residual.values.size());
  expect_rebuilt_as_specified(got->residual);
  // The table: each measured bin's base value corrected by R, escapes exact.
  Model base = *got;
  base.residual = Residual{};
  const BrdfTable with = got->table(), without = base.table();
  for (std::size_t i : {merl_index(3, 45, 77), merl_index(3, 46, 80), merl_index(40, 10, 3)}) {
    ASSERT_FALSE(got->not_measured.test(1, i));
    const double y =
        std::log1p(without.stored(1, i) / 0.5) + got->residual.values[kBinsPerChannel + i];
    EXPECT_EQ(with.stored(1, i), y > 0 ? std::expm1(y) * 0.5 : 0.0) << i;
  }
  Expected<ContainerInfo> info = inspect_container(interp_file());
  ASSERT_TRUE(info.ok()) << info.status().message();
  EXPECT_EQ(info->residual_mode, 3);
  EXPECT_EQ(info->residual_max_error, 0.01 * 16 * 3);  // shifts up to 4, multiplier 3
  EXPECT_EQ(info->residual_min_error, 0.01);
}

TEST(ResidualContainer, MalformedInterpolatedLevelsAreRefused) {
  const Bytes& f = interp_file();
  constexpr std::size_t kLevels = 32 + 8100;  // after the header and the row shifts
  expect_error(with_resd([](Bytes* p) { (*p)[kLevels] = 0; }, 2, false, f), ErrorCode::kCorrupt,
               "level count 0");
  expect_error(with_resd([](Bytes* p) { (*p)[kLevels] = 5; }, 2, false, f), ErrorCode::kCorrupt,
               "level count 5");
  expect_error(with_resd([](Bytes* p) { (*p)[kLevels + 1] = 0; }, 2, false, f), ErrorCode::kNumeric,
               "multiplier 0");
  expect_error(with_resd([](Bytes* p) { (*p)[kLevels + 1] = 65; }, 2, false, f),
               ErrorCode::kNumeric, "multiplier 65");
  // A bound of 1: the rows' 1 x 2^4 is within 16, the finest level's 3 x 16 is not.
  expect_error(with_resd([](Bytes* p) { put_f64(p, 4, 1.0); }, 2, false, f), ErrorCode::kNumeric,
               "finest level's multiplier 3");
  expect_error(with_resd([](Bytes* p) { p->resize(kLevels + 1); }, 2, false, f),
               ErrorCode::kTruncated, "multiplier");
  // A mode 2 payload read as mode 3 takes two code bytes as the levels: refused either way.
  EXPECT_FALSE(decode_model(with_resd([](Bytes* p) { (*p)[0] = 3; }, 2, false, rows_file())).ok());
  // The writer refuses what no reader accepts.
  ContainerSettings s = testing::coding_1_2();
  for (auto edit : std::vector<std::function<void(Residual*)>>{
           [](Residual* r) { r->levels = 5; }, [](Residual* r) { r->fine_multiplier = 0; },
           [](Residual* r) { r->max_error = 1.0; }, [](Residual* r) { r->row_shift.clear(); },
           [](Residual* r) { r->values.clear(); }}) {
    Model bad = interp_model();
    edit(&bad.residual);
    EXPECT_EQ(encode_model(bad, s).status().code(), ErrorCode::kInvalidArgument);
  }
}

// Mode 4 (version 1.3): interp_model()'s codes over 3 levels, the finest level's multiplier 3,
// levels 1 and 2 their own (2 and 5: a coarser level may take the larger one).
Model level_steps_model() {
  Model m = interp_model();
  m.residual.levels = 3;
  m.residual.middle_multipliers = {2, 5, 1};
  internal::rebuild_interpolated(&m.residual);
  return m;
}

const Bytes& level_steps_file() {
  static const Bytes b = [] {
    ContainerSettings s = testing::coding_1_2();
    s.bits = 8;
    s.zstd_level = 3;
    s.format = ContainerSettings::Format::kV13;
    Expected<Bytes> e = encode_model(level_steps_model(), s);
    EXPECT_TRUE(e.ok()) << e.status().message();
    return e.ok() ? *e : Bytes{};
  }();
  return b;
}

TEST(ResidualContainer, LevelStepsRoundTripAndRebuildAsSpecified) {
  const Model want = level_steps_model();
  Expected<Model> got = decode_model(level_steps_file());
  ASSERT_TRUE(got.ok()) << got.status().message();
  EXPECT_EQ(level_steps_file()[10], 3);  // minor version 1.3
  const Bytes payload = payload_of_resd(level_steps_file());
  EXPECT_EQ(payload[0], 4);
  EXPECT_EQ(got->residual.levels, 3);
  EXPECT_EQ(got->residual.fine_multiplier, 3);
  EXPECT_EQ(got->residual.middle_multipliers, (std::array<std::uint8_t, 3>{2, 5, 1}));
  EXPECT_EQ(got->residual.codes, want.residual.codes);
  ASSERT_EQ(got->residual.values.size(), want.residual.values.size());
  EXPECT_EQ(std::memcmp(got->residual.values.data(), want.residual.values.data(),
                        want.residual.values.size() * sizeof(double)),
            0);
  expect_rebuilt_as_specified(got->residual);
  // The multipliers change the rebuild: the same codes in mode 3 rebuild otherwise.
  Model mode3 = want;
  mode3.residual.middle_multipliers = {1, 1, 1};
  internal::rebuild_interpolated(&mode3.residual);
  EXPECT_NE(mode3.residual.values, got->residual.values);
  // Each level's bound: its row's times the level's multiplier.
  const Residual& r = got->residual;
  struct Bin {
    int d, p, level;
    double multiplier;
  };
  for (const Bin& b : {Bin{45, 1, 0, 3}, Bin{44, 3, 0, 3}, Bin{44, 2, 1, 2}, Bin{42, 4, 1, 2},
                       Bin{40, 4, 2, 5}, Bin{44, 0, 2, 5}, Bin{40, 8, 3, 1}, Bin{0, 0, 3, 1}}) {
    const std::size_t i = merl_index(3, b.d, b.p);
    EXPECT_EQ(r.level_of(i), b.level) << b.d << " " << b.p;
    EXPECT_EQ(r.bound_at(i), std::ldexp(0.01, r.row_shift[i / kPhiDBins]) * b.multiplier)
        << b.d << " " << b.p;
  }
  Expected<ContainerInfo> info = inspect_container(level_steps_file());
  ASSERT_TRUE(info.ok()) << info.status().message();
  EXPECT_EQ(info->residual_mode, 4);
  EXPECT_EQ(info->residual_max_error, 0.01 * 16 * 5);  // shifts up to 4, largest multiplier 5
  EXPECT_EQ(info->residual_min_error, 0.01);
}

TEST(ResidualContainer, MalformedLevelStepsAreRefused) {
  const Bytes& f = level_steps_file();
  constexpr std::size_t kLevels = 32 + 8100;  // after the header and the row shifts
  const auto edited = [&](const std::function<void(Bytes*)>& edit) {
    return with_resd(edit, 3, false, f);
  };
  ASSERT_TRUE(decode_model(edited([](Bytes*) {})).ok());
  expect_error(edited([](Bytes* p) { (*p)[kLevels] = 1; }), ErrorCode::kCorrupt,
               "level count 1 at payload offset 8132 is not in 2..4");
  expect_error(edited([](Bytes* p) { (*p)[kLevels + 2] = 0; }), ErrorCode::kNumeric,
               "level 1's multiplier 0 at payload offset 8134");
  expect_error(edited([](Bytes* p) { (*p)[kLevels + 3] = 65; }), ErrorCode::kNumeric,
               "level 2's multiplier 65 at payload offset 8135");
  // A bound of 0.5 keeps the rows within 16 (0.5 x 2^4) and the finest level, set to 1, and
  // level 1 too (2 x 8); level 2's 5 x 8 = 40 passes it.
  expect_error(edited([](Bytes* p) {
                 put_f64(p, 4, 0.5);
                 (*p)[kLevels + 1] = 1;
               }),
               ErrorCode::kNumeric, "level 2's multiplier 5");
  expect_error(edited([](Bytes* p) { p->resize(kLevels + 3); }), ErrorCode::kTruncated,
               "a middle level's multiplier");
  // Mode 4 in a 1.2 file (mode 3's payload, refused before its levels are read).
  expect_error(with_resd([](Bytes* p) { (*p)[0] = 4; }, 2, false, interp_file()),
               ErrorCode::kCorrupt, "residual mode 4 (a step per level) in a version 1.2 file");
  // The writer refuses what no reader accepts: a multiplier out of range, and mode 4 in 1.2.
  ContainerSettings s = testing::coding_1_2();
  s.format = ContainerSettings::Format::kV13;
  for (std::uint8_t bad_m : {std::uint8_t(0), std::uint8_t(65)}) {
    Model bad = level_steps_model();
    bad.residual.middle_multipliers[1] = bad_m;
    EXPECT_EQ(encode_model(bad, s).status().code(), ErrorCode::kInvalidArgument);
  }
  s.format = ContainerSettings::Format::kV12;
  const Status v12 = encode_model(level_steps_model(), s).status();
  EXPECT_EQ(v12.code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(v12.message().find("need container version 1.3"), std::string::npos) << v12.message();
}

// An escape at a not-measured bin.
TEST(ResidualContainer, EscapeAtANotMeasuredBinIsRefused) {
  const Model m = residual_model();
  std::uint32_t masked = 0;
  while (!m.not_measured.test(0, masked)) ++masked;
  Bytes file = with_resd([masked](Bytes* p) {
    // Rewrite the escapes: one, at the first not-measured bin of channel R.
    std::size_t k = p->size();
    // Walk back over the two escapes: value (8) and gap (1..5 bytes) each.
    for (int e = 0; e < 2; ++e) {
      k -= 8;
      --k;
      while (k > 0 && ((*p)[k - 1] & 0x80)) --k;
    }
    p->resize(k);
    ByteWriter w;
    w.varint32(masked);
    w.f64(1.0);
    const Bytes one = w.take();
    p->insert(p->end(), one.begin(), one.end());
    (*p)[28] = 1;  // escape count 1
  });
  expect_error(file, ErrorCode::kCorrupt, "names bin " + std::to_string(masked) + ",");
}

}  // namespace
}  // namespace cbrdf
