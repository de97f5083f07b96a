// SPDX-License-Identifier: MIT
// Model -> .cbrdf bytes -> Model: exactness of everything but the marginals, the quantization
// bound per bits value (pinned from both sides), masks, golden files and measured costs.
#include <gtest/gtest.h>
#include <xxhash.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>

#include "bitstream/residual_levels.h"
#include "cbrdf/codec.h"
#include "cbrdf/container.h"
#include "cbrdf/container_writer.h"
#include "cbrdf/version.h"
#include "coding_1_2.h"
#include "synthetic_model.h"
#include "test_support.h"

namespace cbrdf {
namespace {

using testing::make_model;
using testing::six_slices;

std::vector<std::uint8_t> encode_ok(const Model& m, int bits, int level = 19) {
  ContainerSettings s = testing::coding_1_2();
  s.bits = bits;
  s.zstd_level = level;
  s.source_name = "synthetic";
  Expected<std::vector<std::uint8_t>> bytes = encode_model(m, s);
  EXPECT_TRUE(bytes.ok()) << bytes.status().message();
  return bytes.ok() ? bytes.value() : std::vector<std::uint8_t>{};
}

Model decode_ok(const std::vector<std::uint8_t>& bytes) {
  Expected<Model> m = decode_model(bytes);
  EXPECT_TRUE(m.ok()) << m.status().message();
  return m.ok() ? m.value() : Model{};
}

bool same_bits(double a, double b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

// The bound derived in spec/container.md: e^step - 1, step = (hi - lo) / (2^bits - 2), with
// (lo, hi) the log range of the table scaled to sum 1, widened by float32 rounding.
double derived_bound(const std::vector<double>& t, int bits) {
  double sum = 0, lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double v : t) sum += v;
  for (double v : t) {
    if (v > 0) {
      lo = std::min(lo, std::log(v / sum));
      hi = std::max(hi, std::log(v / sum));
    }
  }
  const double widen = 0x1p-23 * (std::abs(lo) + std::abs(hi));
  return std::expm1((hi - lo + widen) / double((1 << bits) - 2));
}

struct TableError {
  double max_rel = 0, sum_rel = 0;
  std::size_t count = 0;
  double bound_ratio = 0;  // max over tables of (observed max / derived bound)
};

// Checks every table against its bound; zeros must stay exact zeros.
void accumulate_errors(const std::vector<double>& in, const std::vector<double>& out, int bits,
                       TableError* e) {
  ASSERT_EQ(in.size(), out.size());
  double sum = 0;
  for (double v : in) sum += v;
  const double bound = derived_bound(in, bits);
  double table_max = 0;
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (in[i] == 0.0) {
      ASSERT_EQ(out[i], 0.0);
      continue;
    }
    const double rel = std::abs(out[i] / (in[i] / sum) - 1.0);
    ASSERT_LE(rel, bound * (1 + 1e-9) + 1e-13) << "bits " << bits << " bin " << i;
    table_max = std::max(table_max, rel);
    e->sum_rel += rel;
    ++e->count;
  }
  e->max_rel = std::max(e->max_rel, table_max);
  if (bound > 0) e->bound_ratio = std::max(e->bound_ratio, table_max / bound);
}

TableError compare_models(const Model& in, const Model& out, int bits) {
  TableError e;
  EXPECT_EQ(in.slices.size(), out.slices.size());
  for (std::size_t s = 0; s < std::min(in.slices.size(), out.slices.size()); ++s) {
    const Slice &a = in.slices[s], &b = out.slices[s];
    EXPECT_EQ(a.theta_d_begin, b.theta_d_begin);
    EXPECT_EQ(a.theta_d_end, b.theta_d_end);
    for (std::size_t c = 0; c < kChannels; ++c) {
      const ChannelSlice &xc = a.channel[c], &yc = b.channel[c];
      EXPECT_EQ(xc.components(), yc.components());
      for (int r = 0; r < std::min(xc.components(), yc.components()); ++r) {
        const Component &x = xc.component(r), &y = yc.component(r);
        EXPECT_EQ(x.family, y.family);
        EXPECT_TRUE(same_bits(x.theta, y.theta)) << x.theta << " vs " << y.theta;
        EXPECT_TRUE(same_bits(x.scale, y.scale)) << x.scale << " vs " << y.scale;
        accumulate_errors(x.pdf_h, y.pdf_h, bits, &e);
        accumulate_errors(x.pdf_d, y.pdf_d, bits, &e);
        accumulate_errors(x.pdf_p, y.pdf_p, bits, &e);
      }
    }
  }
  EXPECT_EQ(in.not_measured.bits, out.not_measured.bits);
  EXPECT_EQ(in.not_measured.values.size(), out.not_measured.values.size());
  for (std::size_t k = 0;
       k < std::min(in.not_measured.values.size(), out.not_measured.values.size()); ++k) {
    EXPECT_TRUE(same_bits(in.not_measured.values[k], out.not_measured.values[k])) << k;
  }
  return e;
}

TEST(CodecIo, RoundTripEveryBitsValueWithinDerivedBound) {
  const Model m = make_model(six_slices(), /*peaked=*/true, 7);
  for (int bits = 6; bits <= 16; ++bits) {
    SCOPED_TRACE("bits " + std::to_string(bits));
    const Model d = decode_ok(encode_ok(m, bits, 3));
    const TableError e = compare_models(m, d, bits);
    // Pinned from both sides: the worst table comes near its bound, so a bound that goes stale
    // (quantization much better than claimed) fails too.
    EXPECT_GT(e.bound_ratio, 0.3);
    EXPECT_LE(e.bound_ratio, 1.0 + 1e-9);
  }
}

TEST(CodecIo, DecodedTablesSumToOne) {
  const Model d = decode_ok(encode_ok(make_model(six_slices(), true, 3), 8, 3));
  for (const Slice& s : d.slices) {
    for (const ChannelSlice& c : s.channel) {
      for (const auto* t : {&c.pdf_h, &c.pdf_d, &c.pdf_p}) {
        double sum = 0;
        for (double v : *t) sum += v;
        EXPECT_NEAR(sum, 1.0, 1e-12);
      }
    }
  }
}

TEST(CodecIo, ZeroScaleSliceWithZeroTablesAndExactZerosSurvive) {
  Model m = make_model({0, 45, 90}, false, 5);
  ChannelSlice& z = m.slices[1].channel[2];
  z.scale = 0.0;
  std::fill(z.pdf_h.begin(), z.pdf_h.end(), 0.0);
  std::fill(z.pdf_d.begin(), z.pdf_d.end(), 0.0);
  std::fill(z.pdf_p.begin(), z.pdf_p.end(), 0.0);
  // Isolated exact zeros inside a nonzero table, and a uniform table (one distinct value).
  m.slices[0].channel[0].pdf_h[10] = 0.0;
  m.slices[0].channel[0].pdf_h[89] = 0.0;
  std::fill(m.slices[0].channel[1].pdf_p.begin(), m.slices[0].channel[1].pdf_p.end(), 1.0 / 180);
  const Model d = decode_ok(encode_ok(m, 6, 3));
  compare_models(m, d, 6);
  for (double v : d.slices[1].channel[2].pdf_h) EXPECT_EQ(v, 0.0);
  EXPECT_EQ(d.slices[0].channel[0].pdf_h[10], 0.0);
  for (double v : d.slices[0].channel[1].pdf_p) EXPECT_NEAR(v, 1.0 / 180, 1e-17);
}

TEST(CodecIo, StandardMaskCostsAFewBytes) {
  const Model m = make_model(six_slices(), false, 11);
  const std::vector<std::uint8_t> bytes = encode_ok(m, 10);
  Expected<ContainerInfo> info = inspect_container(bytes);
  ASSERT_TRUE(info.ok()) << info.status().message();
  EXPECT_TRUE(info->mask_relative_to_horizon);
  EXPECT_FALSE(info->per_bin_values);
  std::size_t expected_count = 0;
  for (std::uint64_t w : m.not_measured.bits)
    expected_count += std::size_t(__builtin_popcountll(w));
  EXPECT_EQ(info->not_measured_bins, expected_count);
  EXPECT_GT(expected_count, 0u);
  for (const ChunkInfo& c : info->layout.chunks) {
    if (c.tag == kTagMask) {
      EXPECT_LE(c.stored_bytes + kChunkHeaderBytes + kChunkChecksumBytes, 64u);
    }
  }
  compare_models(m, decode_ok(bytes), 10);
}

TEST(CodecIo, RandomMasksWithPerBinValuesRoundTripExactly) {
  std::mt19937_64 rng(42);
  for (double density : {0.0, 1e-5, 0.02, 0.5, 1.0}) {
    SCOPED_TRACE("density " + std::to_string(density));
    Model m = make_model({0, 90}, false, 2);
    m.not_measured = NotMeasured{};
    std::bernoulli_distribution pick(density);
    std::uniform_real_distribution<double> val(-1e6, -1e-300);
    std::size_t count = 0;
    for (int c = 0; c < kChannels; ++c) {
      for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
        if (pick(rng)) {
          m.not_measured.set(c, i);
          ++count;
        }
      }
    }
    m.not_measured.values.clear();
    for (std::size_t k = 0; k < count; ++k) m.not_measured.values.push_back(val(rng));
    if (count > 2) {  // special values must survive bit for bit too
      m.not_measured.values[0] = -std::numeric_limits<double>::infinity();
      m.not_measured.values[1] = -std::numeric_limits<double>::quiet_NaN();
      m.not_measured.values[2] = -std::numeric_limits<double>::denorm_min();
    }
    const std::vector<std::uint8_t> bytes = encode_ok(m, 8, 1);
    compare_models(m, decode_ok(bytes), 8);
  }
}

TEST(CodecIo, GeometricMaskPlusNoiseUsesTheReference) {
  Model m = make_model({0, 90}, false, 2);
  std::mt19937 rng(9);
  for (int k = 0; k < 100; ++k) m.not_measured.set(int(rng() % 3), rng() % kBinsPerChannel);
  const std::vector<std::uint8_t> bytes = encode_ok(m, 8, 3);
  Expected<ContainerInfo> info = inspect_container(bytes);
  ASSERT_TRUE(info.ok());
  EXPECT_TRUE(info->mask_relative_to_horizon);
  compare_models(m, decode_ok(bytes), 8);
}

TEST(CodecIo, InspectDescribesLayoutParametersAndMetadata) {
  const Model m = make_model(six_slices(), true, 4);
  ContainerSettings s = testing::coding_1_2();
  s.bits = 12;
  s.source_name = "blue-metallic-paint.binary";
  Expected<std::vector<std::uint8_t>> bytes = encode_model(m, s);
  ASSERT_TRUE(bytes.ok());
  Expected<ContainerInfo> info = inspect_container(*bytes);
  ASSERT_TRUE(info.ok()) << info.status().message();
  EXPECT_EQ(info->layout.major, kContainerMajorVersion);
  // Without mixtures the writer writes version 1.0, which 1.0 readers read.
  EXPECT_EQ(info->layout.minor, 0);
  EXPECT_EQ(info->layout.file_bytes, bytes->size());
  EXPECT_EQ(info->bits, 12);
  const std::vector<std::string> tags = {"HEAD", "MODL", "MARG", "MASK", "mETA", "CEND"};
  ASSERT_EQ(info->layout.chunks.size(), tags.size());
  std::uint64_t offset = kContainerHeaderBytes;
  for (std::size_t i = 0; i < tags.size(); ++i) {
    const ChunkInfo& c = info->layout.chunks[i];
    EXPECT_EQ(c.tag, tags[i]);
    EXPECT_EQ(c.offset, offset);
    EXPECT_TRUE(c.known);
    offset += kChunkHeaderBytes + c.stored_bytes + kChunkChecksumBytes;
  }
  EXPECT_EQ(offset, bytes->size());
  EXPECT_TRUE(info->layout.chunks[2].compressed);  // MARG always gains from zstd
  ASSERT_EQ(info->slices.size(), m.slices.size());
  for (std::size_t i = 0; i < m.slices.size(); ++i) {
    EXPECT_EQ(info->slices[i].theta_d_end, m.slices[i].theta_d_end);
    for (std::size_t c = 0; c < kChannels; ++c) {
      EXPECT_EQ(info->slices[i].family[c], m.slices[i].channel[c].family);
      EXPECT_EQ(info->slices[i].theta[c], m.slices[i].channel[c].theta);
      EXPECT_EQ(info->slices[i].scale[c], m.slices[i].channel[c].scale);
      EXPECT_EQ(info->slices[i].components[c], 1);
    }
  }
  auto meta = [&](const std::string& k) {
    for (const auto& [key, value] : info->metadata) {
      if (key == k) return value;
    }
    return std::string("<missing>");
  };
  EXPECT_EQ(meta("source"), "blue-metallic-paint.binary");
  EXPECT_EQ(meta("bits"), "12");
  EXPECT_EQ(meta("zstd_level"), "19");
  EXPECT_EQ(meta("encoder"), std::string("cbrdf ") + CBRDF_VERSION_STRING);
}

TEST(CodecIo, MetadataCanBeLeftOutAndHostileSourceNamesAreSanitized) {
  const Model m = make_model({0, 90}, false, 1);
  ContainerSettings s = testing::coding_1_2();
  s.write_metadata = false;
  Expected<std::vector<std::uint8_t>> a = encode_model(m, s);
  ASSERT_TRUE(a.ok());
  Expected<ContainerInfo> ia = inspect_container(*a);
  ASSERT_TRUE(ia.ok());
  EXPECT_TRUE(ia->metadata.empty());
  for (const ChunkInfo& c : ia->layout.chunks) EXPECT_NE(c.tag, kTagMetadata);

  s.write_metadata = true;
  s.source_name = std::string("evil\nbits=99\x01") + std::string(5000, 'x');
  Expected<std::vector<std::uint8_t>> b = encode_model(m, s);
  ASSERT_TRUE(b.ok());
  Expected<ContainerInfo> ib = inspect_container(*b);
  ASSERT_TRUE(ib.ok()) << ib.status().message();
  ASSERT_FALSE(ib->metadata.empty());
  EXPECT_EQ(ib->metadata[0].first, "source");
  EXPECT_EQ(ib->metadata[0].second.substr(0, 13), "evil?bits=99?");
  EXPECT_EQ(ib->metadata[0].second.size(), 1024u);
}

TEST(CodecIo, EncodeRefusesModelsAFileCannotHold) {
  const Model good = make_model(six_slices(), false, 1);
  auto refuse = [](const Model& m, const std::string& needle) {
    Expected<std::vector<std::uint8_t>> r = encode_model(m, testing::coding_1_2());
    ASSERT_FALSE(r.ok()) << needle;
    EXPECT_EQ(r.status().code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(r.status().message().find(needle), std::string::npos) << r.status().message();
  };
  Model m = good;
  m.slices[1].theta_d_begin = 7;
  refuse(m, "contiguous");
  m = good;
  m.slices.back().theta_d_end = 89;
  m.slices.back().channel[0].pdf_d.pop_back();
  m.slices.back().channel[1].pdf_d.pop_back();
  m.slices.back().channel[2].pdf_d.pop_back();
  refuse(m, "not 90");
  m = good;
  m.slices[0].channel[0].family = CopulaFamily::kGumbel;
  m.slices[0].channel[0].theta = 0.5;
  refuse(m, "domain");
  m = good;
  m.slices[0].channel[1].scale = -1.0;
  refuse(m, "scale K");
  m = good;
  m.slices[2].channel[2].pdf_p[3] = std::numeric_limits<double>::quiet_NaN();
  refuse(m, "phi_d table");
  m = good;
  m.slices[2].channel[2].pdf_h.resize(89);
  refuse(m, "theta_h table has 89 values");
  m = good;
  m.not_measured.values = {-1.0, -2.0};
  refuse(m, "values list");
  m = good;
  m.not_measured.values = {0.5};
  refuse(m, "not negative");
  ContainerSettings s = testing::coding_1_2();
  s.bits = 17;
  Expected<std::vector<std::uint8_t>> r = encode_model(good, s);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("bits per code 17"), std::string::npos);
}

// ---- Golden files ---------------------------------------------------------------------------

std::uint64_t model_hash(const Model& m) {
  XXH64_state_t* st = XXH64_createState();
  XXH64_reset(st, 0);
  auto add = [&](const void* p, std::size_t n) { XXH64_update(st, p, n); };
  for (const Slice& s : m.slices) {
    add(&s.theta_d_begin, sizeof s.theta_d_begin);
    add(&s.theta_d_end, sizeof s.theta_d_end);
    for (const ChannelSlice& cs : s.channel) {
      // Components after the first only enter the hash when present, so that the hashes of the
      // version 1.0 golden files did not change when mixtures came.
      for (int r = 0; r < cs.components(); ++r) {
        const Component& c = cs.component(r);
        add(&c.family, 1);
        add(&c.theta, 8);
        add(&c.scale, 8);
        for (const auto* t : {&c.pdf_h, &c.pdf_d, &c.pdf_p}) add(t->data(), t->size() * 8);
      }
    }
  }
  add(m.not_measured.bits.data(), m.not_measured.bits.size() * 8);
  add(m.not_measured.values.data(), m.not_measured.values.size() * 8);
  // The residual (version 1.2) only when present, so that older files' hashes stay.
  if (m.residual.present()) {
    add(&m.residual.max_error, 8);
    add(&m.residual.step, 8);
    add(&m.residual.knee, 8);
    add(m.residual.codes.data(), m.residual.codes.size() * 4);
    for (const ResidualEscape& e : m.residual.escapes) {
      add(&e.bin, 4);
      add(&e.stored, 8);
    }
    // Mode 2's row steps only when present, so that mode 0 files' hashes stay.
    if (!m.residual.row_shift.empty())
      add(m.residual.row_shift.data(), m.residual.row_shift.size());
    // Mode 3's fields and its rebuilt residual (the normative reconstruction) when present.
    if (m.residual.interpolated()) {
      add(&m.residual.levels, 1);
      add(&m.residual.fine_multiplier, 1);
      add(m.residual.values.data(), m.residual.values.size() * 8);
    }
  }
  const std::uint64_t h = XXH64_digest(st);
  XXH64_freeState(st);
  return h;
}

struct Golden {
  const char* name;
  std::uint64_t hash;  // of the decoded model, recorded when the file was written
  int bits;
  Model (*build)();
};

Model golden_frank6() {
  Model m = make_model(six_slices(), true, 2024);
  for (Slice& s : m.slices) {
    for (ChannelSlice& c : s.channel) {
      c.family = CopulaFamily::kFrank;
      c.theta = -c.scale / 100.0;
    }
  }
  return m;
}

std::size_t popcount_all(const NotMeasured& nm) {
  std::size_t n = 0;
  for (std::uint64_t w : nm.bits) n += std::size_t(__builtin_popcountll(w));
  return n;
}

// Two slices, every family, 16 bits, a sparse arbitrary mask with one value per bin.
Model golden_mixed2() {
  Model m = make_model({0, 30, 90}, false, 77);
  m.not_measured = NotMeasured{};
  std::mt19937 rng(5);
  for (int k = 0; k < 200; ++k) {
    // Sequenced: the order in which a call's arguments are evaluated is the compiler's choice (GCC,
    // which wrote the committed file, takes the bin first; clang the channel).
    const std::size_t bin = rng() % kBinsPerChannel;
    const int channel = int(rng() % 3);
    m.not_measured.set(channel, bin);
  }
  m.not_measured.values.clear();
  for (std::size_t k = 0; k < popcount_all(m.not_measured); ++k) {
    m.not_measured.values.push_back(-1.0 - double(k % 7) / 8.0);
  }
  return m;
}

// One slice, 6 bits, no mask at all.
Model golden_tiny1() {
  Model m = make_model({0, 90}, true, 3);
  m.not_measured = NotMeasured{};
  return m;
}

// Version 1.1: a mixture, 1 to 4 components per slice channel (every family), 12 bits.
Model golden_mixture3() {
  return cbrdf::testing::make_mixture_model({0, 20, 50, 90}, 4, 31);
}

// Version 1.2: golden_frank6 with a residual layer: sparse codes of both signs and one escape.
Model golden_residual6() {
  Model m = golden_frank6();
  testing::add_sparse_residual(&m);
  Residual& r = m.residual;
  std::size_t first = 0;
  while (m.not_measured.test(2, first)) ++first;
  r.escapes = {{std::uint32_t(2 * kBinsPerChannel + first), 0.5}};
  return m;
}

// Version 1.2, RESD mode 2: golden_residual6 with a step per row (shifts 0 to 6).
Model golden_rows6() {
  Model m = golden_residual6();
  m.residual.row_shift.resize(std::size_t(kThetaHBins) * kThetaDBins);
  for (std::size_t r = 0; r < m.residual.row_shift.size(); ++r) {
    m.residual.row_shift[r] = std::uint8_t((r / 90 + r % 90) / 30);
  }
  return m;
}

// Version 1.2, RESD mode 3: golden_rows6's codes, plus codes at every coarsest-level bin of every
// tenth theta_h slab, as corrections of an interpolation over 3 levels, finest multiplier 4.
Model golden_interp6() {
  Model m = golden_rows6();
  Residual& r = m.residual;
  r.levels = 3;
  r.fine_multiplier = 4;
  for (int c = 0; c < kChannels; ++c) {
    for (int h = 0; h < kThetaHBins; h += 10) {
      for (int d = 0; d < kThetaDBins; d += 8) {
        for (int p = 0; p < kPhiDBins; p += 8) {
          const std::size_t i = merl_index(h, d, p);
          if (m.not_measured.test(c, i)) continue;
          r.codes[std::size_t(c) * kBinsPerChannel + i] = (h + d + p + c) % 7 - 3;
        }
      }
    }
  }
  internal::rebuild_interpolated(&r);
  return m;
}

const Golden kGolden[] = {
    {"v1.0-frank6-b10.cbrdf", 0x9fe1a1553716af4dull, 10, golden_frank6},
    {"v1.0-mixed2-b16.cbrdf", 0xd135c0c5b1901d9cull, 16, golden_mixed2},
    {"v1.0-tiny1-b6.cbrdf", 0x9f27464498924fe4ull, 6, golden_tiny1},
    {"v1.1-mixture3-b12.cbrdf", 0x1a5a936090db3f8dull, 12, golden_mixture3},
    {"v1.2-residual-frank6-b10.cbrdf", 0x46a06259c1d7b4a3ull, 10, golden_residual6},
    {"v1.2-residual-rows-frank6-b10.cbrdf", 0xb907f23340054a63ull, 10, golden_rows6},
    {"v1.2-residual-interp-frank6-b10.cbrdf", 0x49cdd9ea37766a5dull, 10, golden_interp6},
};

std::vector<std::uint8_t> read_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(in), {});
}

// CBRDF_REGENERATE_GOLDEN=NAME rewrites that file (after an intended format change or for a new
// version), "all" every file, and prints the hashes to record here; otherwise the committed files
// must decode to the recorded hashes. Files of older versions are never rewritten in practice:
// they pin that this reader still reads them.
TEST(CodecIoGolden, CommittedFilesDecodeToRecordedModels) {
  const std::filesystem::path dir = std::filesystem::path(CBRDF_TEST_DATA_DIR) / "golden";
  const char* which = std::getenv("CBRDF_REGENERATE_GOLDEN");
  for (const Golden& g : kGolden) {
    SCOPED_TRACE(g.name);
    const bool regenerate =
        which != nullptr && (std::string(which) == "all" || std::string(which) == g.name);
    const Model built = g.build();
    if (regenerate) {
      ContainerSettings s = testing::coding_1_2();
      s.bits = g.bits;
      s.source_name = g.name;
      Expected<std::vector<std::uint8_t>> bytes = encode_model(built, s);
      ASSERT_TRUE(bytes.ok()) << bytes.status().message();
      std::ofstream(dir / g.name, std::ios::binary)
          .write(reinterpret_cast<const char*>(bytes->data()), std::streamsize(bytes->size()));
    }
    const std::vector<std::uint8_t> bytes = read_bytes(dir / g.name);
    ASSERT_FALSE(bytes.empty()) << "missing golden file " << (dir / g.name);
    Expected<Model> decoded = decode_model(bytes);
    ASSERT_TRUE(decoded.ok()) << decoded.status().message();
    compare_models(built, *decoded, g.bits);
    // The encoder is pinned too: re-encoding gives the same payloads (compared decompressed, so
    // a different zstd version does not matter; mETA names the encoder version and is left out).
    ContainerSettings s = testing::coding_1_2();
    s.bits = g.bits;
    Expected<std::vector<std::uint8_t>> again = encode_model(built, s);
    ASSERT_TRUE(again.ok());
    Expected<ParsedContainer> committed = parse_container(bytes), fresh = parse_container(*again);
    ASSERT_TRUE(committed.ok() && fresh.ok());
    for (std::string_view tag : {kTagHeader, kTagModel, kTagMarginals, kTagMask, kTagResidual}) {
      ASSERT_EQ(committed->find(tag) >= 0, fresh->find(tag) >= 0) << tag;
      if (committed->find(tag) < 0) continue;
      EXPECT_EQ(committed->payloads[std::size_t(committed->find(tag))],
                fresh->payloads[std::size_t(fresh->find(tag))])
          << "the encoder's " << tag << " payload changed";
    }
    EXPECT_EQ(decoded->residual.codes, built.residual.codes);
    EXPECT_EQ(decoded->residual.values, built.residual.values);
    const std::uint64_t h = model_hash(*decoded);
    if (regenerate) std::printf("%s 0x%016llxull\n", g.name, static_cast<unsigned long long>(h));
    EXPECT_EQ(h, g.hash) << std::hex << "decoded hash 0x" << h
                         << ": the format or the decoder changed";
  }
}

// ---- Measurements ---------------------------------------------------------------------------

std::uint32_t chunk_bytes(const ContainerInfo& info, std::string_view tag) {
  for (const ChunkInfo& c : info.layout.chunks) {
    if (c.tag == tag)
      return std::uint32_t(kChunkHeaderBytes + c.stored_bytes + kChunkChecksumBytes);
  }
  return 0;
}

// Prints what each bit costs and gains, and checks the trend: more bits, more bytes, less error.
void measure(const char* label, const Model& m) {
  std::printf("\n%s\nbits  file  HEAD  MODL  MARG  MASK  mETA  max_rel_err  mean_rel_err\n", label);
  std::size_t prev_bytes = 0;
  double prev_err = 1e9;
  for (int bits = 6; bits <= 16; ++bits) {
    const std::vector<std::uint8_t> bytes = encode_ok(m, bits);
    Expected<ContainerInfo> info = inspect_container(bytes);
    ASSERT_TRUE(info.ok());
    const TableError e = compare_models(m, decode_ok(bytes), bits);
    std::printf("%4d %5zu %5u %5u %5u %5u %5u  %11.3e  %12.3e\n", bits, bytes.size(),
                chunk_bytes(*info, "HEAD"), chunk_bytes(*info, "MODL"), chunk_bytes(*info, "MARG"),
                chunk_bytes(*info, "MASK"), chunk_bytes(*info, "mETA"), e.max_rel,
                e.sum_rel / double(e.count));
    EXPECT_GE(bytes.size() + 8, prev_bytes);  // zstd may shave a few bytes off a wider code
    EXPECT_LT(e.max_rel, prev_err);
    prev_bytes = bytes.size();
    prev_err = e.max_rel;
  }
}

TEST(CodecIoMeasure, BytesAndErrorPerBitSynthetic) {
  measure("6-slice synthetic model, smooth lobes", make_model(six_slices(), false, 21));
  measure("6-slice synthetic model, channel G near-mirror (3 bins, 1e-12 elsewhere)",
          make_model(six_slices(), true, 21));
}

// Marginals of a real material: per slice and channel, the sums of measured physical values
// along the other two axes (what the fitter's empirical marginals are, up to imputation).
Model model_from_merl(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::int32_t dims[3];
  in.read(reinterpret_cast<char*>(dims), sizeof dims);
  std::vector<double> v(std::size_t(kChannels) * kBinsPerChannel);
  in.read(reinterpret_cast<char*>(v.data()), std::streamsize(v.size() * 8));
  Model m;
  NotMeasured nm;
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (v[std::size_t(c) * kBinsPerChannel + i] < 0) nm.set(c, i);
    }
  }
  nm.values = {-1.0};
  m.not_measured = nm;
  const std::vector<int>& b = six_slices();
  for (std::size_t s = 0; s + 1 < b.size(); ++s) {
    Slice sl;
    sl.theta_d_begin = b[s];
    sl.theta_d_end = b[s + 1];
    for (int c = 0; c < kChannels; ++c) {
      ChannelSlice& cs = sl.channel[std::size_t(c)];
      cs.family = CopulaFamily::kFrank;
      cs.theta = -3.0;
      cs.pdf_h.assign(kThetaHBins, 0);
      cs.pdf_d.assign(std::size_t(sl.width()), 0);
      cs.pdf_p.assign(kPhiDBins, 0);
      for (int h = 0; h < kThetaHBins; ++h) {
        for (int d = sl.theta_d_begin; d < sl.theta_d_end; ++d) {
          for (int p = 0; p < kPhiDBins; ++p) {
            const double x = v[std::size_t(c) * kBinsPerChannel + merl_index(h, d, p)];
            if (x <= 0) continue;
            const double phys = x * kMerlScale[std::size_t(c)];
            cs.pdf_h[std::size_t(h)] += phys;
            cs.pdf_d[std::size_t(d - sl.theta_d_begin)] += phys;
            cs.pdf_p[std::size_t(p)] += phys;
            cs.scale += phys;
          }
        }
      }
      for (auto* t : {&cs.pdf_h, &cs.pdf_d, &cs.pdf_p}) {
        if (cs.scale > 0) testing::normalize(t);
      }
    }
    m.slices.push_back(sl);
  }
  return m;
}

TEST(CodecIoMeasure, BytesAndErrorPerBitRealMaterials) {
  const std::filesystem::path dir = testing::real_materials_dir();
  if (dir.empty()) GTEST_SKIP() << "no ../shared real materials: real-data measurement skipped";
  for (const char* name : {"chrome-steel", "blue-metallic-paint", "beige-fabric"}) {
    const std::filesystem::path f = dir / (std::string(name) + ".binary");
    if (!std::filesystem::exists(f)) GTEST_SKIP() << "missing real material " << f;
    measure((std::string("real material ") + name + ", 6 slices").c_str(), model_from_merl(f));
  }
}

// decode_model with an info gives what inspect_container gives, from the same single pass.
TEST(CodecIoGolden, DecodeModelDescribesTheFileAsInspectDoes) {
  const std::filesystem::path dir = std::filesystem::path(CBRDF_TEST_DATA_DIR) / "golden";
  for (const Golden& g : kGolden) {
    SCOPED_TRACE(g.name);
    const std::vector<std::uint8_t> bytes = read_bytes(dir / g.name);
    Expected<ContainerInfo> inspected = inspect_container(bytes);
    ContainerInfo info;
    Expected<Model> model = decode_model(bytes, &info);
    ASSERT_TRUE(inspected.ok() && model.ok());
    EXPECT_EQ(info.bits, inspected->bits);
    EXPECT_EQ(info.layout.file_bytes, inspected->layout.file_bytes);
    EXPECT_EQ(info.layout.chunks.size(), inspected->layout.chunks.size());
    EXPECT_EQ(info.slices.size(), inspected->slices.size());
    EXPECT_EQ(info.not_measured_bins, inspected->not_measured_bins);
    EXPECT_EQ(info.metadata, inspected->metadata);
    EXPECT_EQ(model_hash(*model), g.hash);
  }
}

}  // namespace
}  // namespace cbrdf
