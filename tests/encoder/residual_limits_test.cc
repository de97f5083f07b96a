// SPDX-License-Identifier: MIT
// Issue 31's format limits: every accepted RESD evaluates and samples finite (spec 4.6, the
// residual limit), parameters stay inside the encoder's fit ranges (spec 4.2), and the residual
// bound and footprint are reported as one true number everywhere.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "bitstream/chunks.h"
#include "bitstream/quantize.h"
#include "bitstream/residual_levels.h"
#include "byte_writer.h"
#include "cbrdf/cbrdf_c.h"
#include "cbrdf/codec.h"
#include "cbrdf/container.h"
#include "cbrdf/container_writer.h"
#include "cbrdf/sampling.h"
#include "coding_1_2.h"
#include "density/grid_copula.h"
#include "synthetic_model.h"

namespace cbrdf {
namespace {

using Bytes = std::vector<std::uint8_t>;
constexpr double kDblMax = std::numeric_limits<double>::max();

// The file of `base` with a hand-made RESD payload (any content: the writer's checks bypassed),
// as a hostile file would be, version 1.2.
Bytes file_with_resd(const Model& base, const Bytes& resd) {
  ContainerSettings s = testing::coding_1_2();
  s.bits = 8;
  s.zstd_level = 3;
  // Written with a valid all-zero residual (a 1.2 file), whose RESD payload is then replaced.
  Model with = base;
  with.residual.max_error = 0.01;
  with.residual.step = 0.02;
  with.residual.knee = 1e-4;
  with.residual.codes.assign(kMaskBits, 0);
  Expected<Bytes> plain = encode_model(with, s);
  EXPECT_TRUE(plain.ok()) << plain.status().message();
  Expected<ParsedContainer> pc = parse_container(*plain);
  EXPECT_TRUE(pc.ok());
  std::vector<ChunkToWrite> chunks;
  for (std::size_t k = 0; k + 1 < pc->layout.chunks.size(); ++k) {
    chunks.push_back({pc->layout.chunks[k].tag, pc->payloads[k], true});
    if (chunks.back().tag == kTagResidual) chunks.back().payload = resd;
  }
  Expected<Bytes> out = write_container(chunks, 3, 2);  // version 1.2
  EXPECT_TRUE(out.ok()) << out.status().message();
  return out.ok() ? *out : Bytes{};
}

// A RESD payload of mode 0 or 2 (shift given: every row that shift) with every measured bin's
// code `code`, predictor 0.
Bytes resd_payload(const Model& m, double max_error, double step, double knee, std::int32_t code,
                   int shift = -1) {
  ByteWriter w;
  w.u8(shift < 0 ? kResidualModeLog : kResidualModeRows);
  w.u8(kResidualPredictorNone);
  w.u16(0);
  w.f64(max_error);
  w.f64(step);
  w.f64(knee);
  w.u32(0);
  if (shift >= 0) w.bytes(std::vector<std::uint8_t>(kResidualRows, std::uint8_t(shift)));
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (!m.not_measured.test(c, i)) w.varint32(zigzag(code));
    }
  }
  return w.take();
}

Model base_model() {
  return testing::make_model(testing::six_slices(), true, 11);
}

// Sample weights of 600,000 draws over a spread of outgoing directions, through the C API (what a
// renderer calls); all must be finite and >= 0, and so must the values.
void expect_finite_sampling(const Bytes& file) {
  cbrdf_model* h = cbrdf_model_open_memory(file.data(), file.size());
  ASSERT_NE(h, nullptr) << cbrdf_last_error_message();
  constexpr std::size_t n = 600000;
  std::vector<double> wo(3 * n), u(2 * n), wi(3 * n), pdf(n), weight(3 * n), rgb(3 * n);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  for (std::size_t k = 0; k < n; ++k) {
    const double z = 0.02 + 0.98 * uni(rng), phi = 6.283185307179586 * uni(rng);
    const double r = std::sqrt(1 - z * z);
    wo[3 * k] = r * std::cos(phi);
    wo[3 * k + 1] = r * std::sin(phi);
    wo[3 * k + 2] = z;
    u[2 * k] = uni(rng);
    u[2 * k + 1] = uni(rng);
  }
  ASSERT_EQ(
      cbrdf_model_sample_batch(h, n, wo.data(), u.data(), wi.data(), pdf.data(), weight.data(), 0),
      CBRDF_OK);
  std::size_t bad = 0;
  for (double x : weight) bad += !(std::isfinite(x) && x >= 0.0);
  EXPECT_EQ(bad, 0u) << "non-finite or negative sample weights";
  for (std::size_t k = 0; k < n; ++k) {
    if (!(pdf[k] > 0)) std::memcpy(&wi[3 * k], &wo[3 * k], 3 * sizeof(double));
  }
  ASSERT_EQ(cbrdf_model_eval_batch(h, n, wi.data(), wo.data(), rgb.data(), 0), CBRDF_OK);
  bad = 0;
  for (double x : rgb) bad += !(std::isfinite(x) && x >= 0.0);
  EXPECT_EQ(bad, 0u) << "non-finite or negative values";
  cbrdf_model_free(h);
}

// Item 10: the issue's file (E = 16, step 32, every code +2^28) decoded and sampled +inf weights;
// now its residual (2^33 in log1p units) is refused, as are mode 2 rows that reach past the limit.
TEST(ResidualLimits, ResidualsBeyondTheLimitAreRefused) {
  const Model m = base_model();
  const Bytes issue = file_with_resd(m, resd_payload(m, 16.0, 32.0, 1e-4, 1 << 28));
  Expected<Model> got = decode_model(issue);
  ASSERT_FALSE(got.ok());
  EXPECT_EQ(got.status().code(), ErrorCode::kNumeric);
  EXPECT_NE(got.status().message().find("beyond +-64"), std::string::npos)
      << got.status().message();
  EXPECT_NE(got.status().message().find("RESD"), std::string::npos);
  // Mode 2, shift 10: step 2^-5 x 2^10 = 32 per code, so code 3 is 96.
  const Bytes rows = file_with_resd(m, resd_payload(m, 1.0 / 64, 1.0 / 32, 1e-4, 3, 10));
  EXPECT_EQ(decode_model(rows).status().code(), ErrorCode::kNumeric);
  // Just past the limit: 3 x 21.4 = 64.2 (a valid step, at most 2 E = 32).
  const Bytes edge = file_with_resd(m, resd_payload(m, 16.0, 21.4, 1e-4, 3));
  EXPECT_EQ(decode_model(edge).status().code(), ErrorCode::kNumeric);
  // The writer refuses what the reader would.
  Model w = m;
  w.residual.max_error = 16;
  w.residual.step = 32;
  w.residual.knee = 1e-4;
  w.residual.codes.assign(kMaskBits, 0);
  for (std::size_t b = 0; b < kMaskBits; ++b) {
    if (!mask_bit(w.not_measured.bits, b)) w.residual.codes[b] = 3;
  }
  EXPECT_EQ(encode_model(w, testing::coding_1_2()).status().code(), ErrorCode::kInvalidArgument);
}

// Item 10: a file at the limit everywhere (every residual +64, the largest knee) is valid and
// evaluates and samples finite; so does the most negative one.
TEST(ResidualLimits, FilesAtTheLimitEvaluateAndSampleFinite) {
  const Model m = base_model();
  for (std::int32_t code : {2, -2}) {
    SCOPED_TRACE(code);
    const Bytes f = file_with_resd(m, resd_payload(m, 16.0, 32.0, 1e12, code));
    Expected<Model> got = decode_model(f);
    ASSERT_TRUE(got.ok()) << got.status().message();
    const BrdfTable t = got->table();
    for (double v : t.stored_values()) ASSERT_TRUE(std::isfinite(v) || std::isnan(v) || v < 0);
    expect_finite_sampling(f);
  }
}

// Item 10, mode 3: codes that each stay small but accumulate along the coarsest level's chain past
// the limit are refused once rebuilt.
TEST(ResidualLimits, InterpolatedResidualsAreCheckedAfterTheRebuild) {
  const Model m = base_model();
  ByteWriter w;
  w.u8(kResidualModeInterp);
  w.u8(kResidualPredictorNone);
  w.u16(0);
  w.f64(1.0);  // E
  w.f64(2.0);  // step
  w.f64(1e-4);
  w.u32(0);
  w.bytes(std::vector<std::uint8_t>(kResidualRows, 0));
  w.u8(1);  // one level: the coarsest nodes every 2nd bin, 90 of them along phi_d
  w.u8(1);
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      // +1 code (2.0) at each coarsest node: the chain sums to 180 > 64.
      const bool coarse = (i % kPhiDBins) % 2 == 0 && (i / kPhiDBins % kThetaDBins) % 2 == 0;
      if (!m.not_measured.test(c, i)) w.varint32(zigzag(coarse ? 1 : 0));
    }
  }
  const Bytes f = file_with_resd(m, w.take());
  Expected<Model> got = decode_model(f);
  ASSERT_FALSE(got.ok());
  EXPECT_EQ(got.status().code(), ErrorCode::kNumeric);
  EXPECT_NE(got.status().message().find("rebuilt level by level"), std::string::npos)
      << got.status().message();
}

// Item 11: a file may hold only parameters inside the encoder's fit ranges: the issue's Frank at
// -DBL_MAX (3.4 to 7.0 s to decode at 90 slices x 8 components) is refused before any work.
TEST(ParameterRanges, ParametersBeyondTheFitRangesAreRefused) {
  struct Case {
    CopulaFamily family;
    double ok_edge, beyond;
  };
  const Case cases[] = {
      {CopulaFamily::kFrank, -200.0, -200.5}, {CopulaFamily::kFrank, -200.0, -kDblMax},
      {CopulaFamily::kClayton, 50.0, 50.5},   {CopulaFamily::kClayton, 50.0, 1e300},
      {CopulaFamily::kGumbel, 20.0, 20.5},    {CopulaFamily::kJoe, 20.0, kDblMax}};
  for (const Case& c : cases) {
    SCOPED_TRACE(std::string(family_name(c.family)) + " " + std::to_string(c.beyond));
    EXPECT_TRUE(copula_parameter_valid(c.family, c.ok_edge));
    EXPECT_FALSE(copula_parameter_valid(c.family, c.beyond));
    Model m = testing::make_model(testing::six_slices());
    for (Slice& s : m.slices) {
      for (ChannelSlice& cs : s.channel) {
        cs.family = c.family;
        cs.theta = c.ok_edge;
      }
    }
    Expected<Bytes> ok = encode_model(m, testing::coding_1_2());
    ASSERT_TRUE(ok.ok()) << ok.status().message();
    EXPECT_TRUE(decode_model(*ok).ok());
    // The same file with the last slice's blue parameter moved past the range (MODL patched).
    m.slices.back().channel[2].theta = c.beyond;
    EXPECT_EQ(encode_model(m, testing::coding_1_2()).status().code(), ErrorCode::kInvalidArgument);
    Expected<ParsedContainer> pc = parse_container(*ok);
    ASSERT_TRUE(pc.ok());
    std::vector<ChunkToWrite> chunks;
    for (std::size_t k = 0; k + 1 < pc->layout.chunks.size(); ++k) {
      chunks.push_back({pc->layout.chunks[k].tag, pc->payloads[k], true});
      if (chunks.back().tag == kTagModel) {
        Bytes& p = chunks.back().payload;
        // MODL: S slice ends, then per slice and channel u8 family, f64 theta, f64 K.
        const std::size_t at = m.slices.size() + (m.slices.size() * 3 - 1) * 17 + 1;
        double old = 0;
        std::memcpy(&old, &p[at], 8);
        ASSERT_EQ(old, c.ok_edge);
        std::memcpy(&p[at], &c.beyond, 8);
      }
    }
    Expected<Bytes> bad = write_container(chunks, 3, (*ok)[10]);
    ASSERT_TRUE(bad.ok());
    Expected<Model> got = decode_model(*bad);
    ASSERT_FALSE(got.ok());
    EXPECT_EQ(got.status().code(), ErrorCode::kNumeric);
    EXPECT_NE(got.status().message().find("domain a file may hold"), std::string::npos)
        << got.status().message();
  }
}

// Item 11: the format's ranges are the encoder's fit ranges, so the encoder never writes beyond
// them and every valid file's parameters are ones it can write.
TEST(ParameterRanges, FormatRangesAreTheFitRanges) {
  for (CopulaFamily f : {CopulaFamily::kFrank, CopulaFamily::kClayton, CopulaFamily::kGumbel,
                         CopulaFamily::kJoe, CopulaFamily::kIndependence}) {
    const auto grid = internal::make_grid_copula(f);
    EXPECT_TRUE(copula_parameter_valid(f, grid->search_lo()));
    EXPECT_TRUE(copula_parameter_valid(f, grid->search_hi()));
    EXPECT_FALSE(copula_parameter_valid(f, std::nextafter(grid->search_lo(), -kDblMax)));
    EXPECT_FALSE(copula_parameter_valid(f, std::nextafter(grid->search_hi(), kDblMax)));
  }
}

// Item 4: one bound, met by every bin: Residual::bound(), inspect_container and the C API agree
// on a mode 3 file with row shifts and a finest multiplier (where the bound is m E 2^max shift).
TEST(ResidualBound, OneNumberEverywhere) {
  Model m = base_model();
  Residual& r = m.residual;
  r.max_error = 0.01;
  r.step = 0.0199;
  r.knee = 1e-4;
  r.row_shift.assign(kResidualRows, 0);
  for (std::size_t row = 0; row < kResidualRows; row += 7) r.row_shift[row] = 3;
  r.levels = 3;
  r.fine_multiplier = 8;
  r.codes.assign(kMaskBits, 0);
  for (std::size_t b = 0; b < kMaskBits; b += 13) {
    if (!mask_bit(m.not_measured.bits, b)) r.codes[b] = std::int32_t(b % 5) - 2;
  }
  internal::rebuild_interpolated(&r);
  const double expected = 8 * 0.01 * 8;  // m x E x 2^3
  EXPECT_EQ(r.bound(), expected);
  double largest = 0;
  for (std::size_t i = 0; i < kBinsPerChannel; ++i) largest = std::max(largest, r.bound_at(i));
  EXPECT_EQ(largest, expected);
  ContainerSettings s = testing::coding_1_2();
  s.zstd_level = 3;
  Expected<Bytes> f = encode_model(m, s);
  ASSERT_TRUE(f.ok()) << f.status().message();
  Expected<ContainerInfo> info = inspect_container(*f);
  ASSERT_TRUE(info.ok());
  EXPECT_EQ(info->residual_max_error, expected);
  cbrdf_model* h = cbrdf_model_open_memory(f->data(), f->size());
  ASSERT_NE(h, nullptr);
  cbrdf_model_info ci{};
  ci.struct_size = sizeof ci;
  ASSERT_EQ(cbrdf_model_get_info(h, &ci), CBRDF_OK);
  EXPECT_EQ(ci.residual_max_error, expected);
  cbrdf_model_free(h);
  // Mode 0: E itself; mode 1 and none: 0.
  Residual plain;
  plain.max_error = 0.25;
  EXPECT_EQ(plain.bound(), 0.25);
  EXPECT_EQ(Residual{}.bound(), 0.0);
}

// Item 7: the footprint counts the residual the evaluator reads (codes, rebuilt values, the exact
// table), not only the evaluator object: before, every residual model reported 463,752 bytes.
TEST(ResidualFootprint, CountsTheResidual) {
  Model m = base_model();
  const std::size_t plain = ModelEvaluator(m).footprint_bytes();
  m.residual.max_error = 0.01;
  m.residual.step = 0.0199;
  m.residual.knee = 1e-4;
  m.residual.codes.assign(kMaskBits, 0);
  const std::size_t mode0 = ModelEvaluator(m).footprint_bytes();
  EXPECT_GE(mode0, plain + kMaskBits * sizeof(std::int32_t));
  m.residual.row_shift.assign(kResidualRows, 0);
  m.residual.levels = 2;
  internal::rebuild_interpolated(&m.residual);
  const std::size_t mode3 = ModelEvaluator(m).footprint_bytes();
  EXPECT_GE(mode3, plain + kMaskBits * (sizeof(std::int32_t) + sizeof(double)));
  Model exact = base_model();
  exact.residual.exact = std::make_shared<const BrdfTable>(exact.table());
  EXPECT_GE(ModelEvaluator(exact).footprint_bytes(), plain + kMaskBits * sizeof(double));
}

// Item 12: a corrupt exact table's message names it once ("exact table: exact table ..." before).
TEST(ResidualMessages, ExactTableErrorsAreNamedOnce) {
  Model m = testing::make_model({0, 45, 90}, false, 3);
  testing::set_standard_mask(&m);
  m.residual.exact = std::make_shared<const BrdfTable>(m.table());
  ContainerSettings s = testing::coding_1_2();
  s.zstd_level = 3;
  Expected<Bytes> f = encode_model(m, s);
  ASSERT_TRUE(f.ok()) << f.status().message();
  Expected<ParsedContainer> pc = parse_container(*f);
  ASSERT_TRUE(pc.ok());
  int tried = 0, named = 0;
  for (std::size_t cut = 2; cut < 64; cut += 3) {
    std::vector<ChunkToWrite> chunks;
    for (std::size_t k = 0; k + 1 < pc->layout.chunks.size(); ++k) {
      chunks.push_back({pc->layout.chunks[k].tag, pc->payloads[k], true});
      if (chunks.back().tag == kTagResidual) chunks.back().payload[cut] ^= 0x5A;
    }
    Expected<Bytes> bad = write_container(chunks, 3, 2);
    ASSERT_TRUE(bad.ok());
    Expected<Model> got = decode_model(*bad);
    if (got.ok()) continue;
    ++tried;
    const std::string& msg = got.status().message();
    EXPECT_EQ(msg.find("exact table: exact table"), std::string::npos) << msg;
    named += msg.find("exact table") != std::string::npos;
  }
  EXPECT_GT(tried, 5);
  EXPECT_EQ(named, tried);
}

}  // namespace
}  // namespace cbrdf
