// SPDX-License-Identifier: MIT
// Issue 40, item 5: a table's overall scale changes nothing but the scale of what it decodes to,
// in every container version (spec 7, "Supported values"). Container 1.3 held K as binary32, so a
// table scaled by 1e-50 was written, by default, as a file whose every K was 0: it decoded to
// zeros (12.58 dB tone-mapped against 43.75 dB unscaled) without a word.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "bitstream/chunk_writers.h"
#include "cbrdf/codec.h"
#include "cbrdf/container.h"
#include "cbrdf/container_writer.h"
#include "cbrdf/encoder.h"
#include "cbrdf/encoder_options.h"
#include "cbrdf/noise.h"
#include "coding_1_2.h"
#include "metrics.h"
#include "refused.h"
#include "synthetic_model.h"
#include "table_builder.h"

namespace cbrdf {
namespace {

// A synthetic glossy material (a specular lobe in theta_h over a diffuse floor, a Fresnel-like
// rise in theta_d, a little phi_d dependence, each channel its own) whose largest stored value in
// each channel is exactly 1, so that scaling by k puts every channel's largest value at k.
BrdfTable unit_peak_table() {
  BrdfTable t = testing::make_table([](int c, int th, int td, int pd) {
    const double h = theta_h_of(th), d = theta_d_of(td), p = phi_d_of(pd);
    const double lobe = std::exp(-h * h / (0.04 + 0.02 * c));
    const double fresnel = 1.0 + 2.0 * std::pow(1.0 - std::cos(d), 5.0);
    return (0.05 + 0.02 * c) * (1.0 + 0.1 * std::cos(2.0 * p)) + 3.0 * lobe * fresnel;
  });
  std::vector<double>& v = t.stored_values();  // channel-major
  for (std::size_t c = 0; c < std::size_t{kChannels}; ++c) {
    const auto begin = v.begin() + std::ptrdiff_t(c * kBinsPerChannel);
    const double peak = *std::max_element(begin, begin + std::ptrdiff_t(kBinsPerChannel));
    for (auto it = begin; it != begin + std::ptrdiff_t(kBinsPerChannel); ++it) {
      if (*it >= 0) *it /= peak;
    }
  }
  return t;
}

std::string text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

BrdfTable scaled(const BrdfTable& t, double k) {
  BrdfTable out = t;
  for (double& v : out.stored_values()) {
    if (v >= 0) v *= k;
  }
  return out;
}

// The command's defaults (encoder_settings: container version auto, as for Python and the C API),
// with few slices and fixed bits so that the sweep stays fast.
EncoderSettings settings(const std::string& format_version, double max_error = 0) {
  EncoderOptions o;
  o.slices = "2";
  o.bits = "8";
  o.format_version = format_version;
  o.max_error = max_error;
  o.threads = 2;
  Expected<EncoderSettings> st = encoder_settings(o);
  EXPECT_TRUE(st.ok()) << st.status().message();
  return *st;
}

int minor_version(const std::vector<std::uint8_t>& bytes) {
  Expected<ContainerLayout> v = read_container_version(bytes);
  EXPECT_TRUE(v.ok()) << v.status().message();
  return v.ok() ? v->minor : -1;
}

struct Scored {
  double tonemapped = 0, linear = 0;
  int minor = -1;
};

// Fits the scaled table once (the container version does not change the fit) and writes the fit
// in each version: as the default writes it (auto), as 1.2 and as 1.3; each file decoded and
// scored against the scaled table.
std::array<Scored, 3> encode_in_every_version(const BrdfTable& table) {
  std::array<Scored, 3> out{};
  Expected<EncodeResult> r = encode_table(table, settings("auto"));
  EXPECT_TRUE(r.ok()) << r.status().message();
  if (!r.ok()) return out;
  const SphereScorer scorer(table);
  const std::string names[3] = {"auto", "1.2", "1.3"};
  for (std::size_t v = 0; v < 3; ++v) {
    SCOPED_TRACE("format version " + names[v]);
    std::vector<std::uint8_t> bytes = r->bytes;
    if (v > 0) {
      ContainerSettings cs = settings(names[v]).container;
      cs.bits = r->bits;
      Expected<std::vector<std::uint8_t>> b = encode_model(r->model, cs);
      EXPECT_TRUE(b.ok()) << b.status().message();
      if (!b.ok()) continue;
      bytes = std::move(*b);
    }
    Expected<Model> m = decode_model(bytes);
    EXPECT_TRUE(m.ok()) << m.status().message();
    if (!m.ok()) continue;
    const ImageMetrics im = scorer.score(*m);
    out[v] = {im.psnr_tonemapped, im.psnr_linear, minor_version(bytes)};
  }
  return out;
}

// Inside the supported range (largest value 1e-250 to 1e250) every version decodes within
// 0.05 dB of the unscaled table's PSNR, and the default keeps the version it writes at scale 1.
TEST(ScaleRange, EveryVersionDecodesEveryScaleAsTheUnscaledTable) {
  const BrdfTable unit = unit_peak_table();
  const std::array<Scored, 3> ref = encode_in_every_version(unit);
  EXPECT_EQ(ref[0].minor, 3);  // the default writes 1.3 for this model
  EXPECT_LE(ref[1].minor, 2);
  EXPECT_EQ(ref[2].minor, 3);
  for (const Scored& s : ref) EXPECT_GT(s.tonemapped, 30.0);
  for (double k : {1e-250, 1e-100, 1e-50, 1e-46, 1e-40, 1e-38, 1e40, 1e100, 1e250}) {
    SCOPED_TRACE("scale " + text(k));
    const std::array<Scored, 3> got = encode_in_every_version(scaled(unit, k));
    for (std::size_t v = 0; v < 3; ++v) {
      SCOPED_TRACE("version index " + std::to_string(v));
      EXPECT_NEAR(got[v].tonemapped, ref[v].tonemapped, 0.05);
      EXPECT_NEAR(got[v].linear, ref[v].linear, 0.05);
      EXPECT_EQ(got[v].minor, ref[v].minor);
    }
  }
}

// Beyond the supported range the encoder refuses with the range in the message, whatever the
// version asked for: never a file that decodes to zeros or to the largest double.
TEST(ScaleRange, TablesBeyondTheRangeAreRefusedInEveryVersion) {
  const BrdfTable unit = unit_peak_table();
  for (double k : {1e-300, 1e300}) {
    for (const char* v : {"auto", "1.2", "1.3"}) {
      SCOPED_TRACE(text(k) + " " + v);
      Expected<EncodeResult> r = encode_table(scaled(unit, k), settings(v));
      ASSERT_FALSE(r.ok());
      EXPECT_EQ(r.status().code(), ErrorCode::kNumeric);
      EXPECT_NE(r.status().message().find("supported range (1e-250 to 1e+250"), std::string::npos)
          << r.status().message();
    }
  }
}

// The residual layer's bound is relative (log1p over a knee, spec 4.6). Below a largest value of 1
// the knee scales with the table, so a tiny table gets what the same table at 1/2 gets; from 1 up
// the knee is the measured 1e-4 stored units, far below a bright table's values, which then gets
// the same too (measured: 55.27 dB tone-mapped and 14.2 KB at 1/2, 1e-50 and 1e250; 55.14 dB at
// 1, where the knee is inside the table's range).
double residual_psnr(const BrdfTable& unit, double k) {
  SCOPED_TRACE("scale " + text(k));
  const BrdfTable t = scaled(unit, k);
  Expected<EncodeResult> r = encode_table(t, settings("auto", 0.05));
  EXPECT_TRUE(r.ok()) << r.status().message();
  if (!r.ok()) return 0;
  EXPECT_EQ(minor_version(r->bytes), 3);  // mode 4 and range-coded codes: 1.3 only
  Expected<Model> m = decode_model(r->bytes);
  EXPECT_TRUE(m.ok()) << m.status().message();
  if (!m.ok()) return 0;
  EXPECT_TRUE(m->residual.present());
  return SphereScorer(t).score(*m).psnr_tonemapped;
}

TEST(ScaleRange, ResidualLayerKeepsItsPsnrAtEveryScale) {
  const BrdfTable unit = unit_peak_table();
  const double below_one = residual_psnr(unit, 0.5);
  EXPECT_GT(below_one, 40.0);
  EXPECT_NEAR(residual_psnr(unit, 1e-50), below_one, 0.05);
  EXPECT_NEAR(residual_psnr(unit, 1e250), below_one, 0.05);
}

// The noise estimate is a relative deviation: the same at every scale.
TEST(ScaleRange, NoiseEstimateDoesNotDependOnTheScale) {
  const BrdfTable unit = unit_peak_table();
  NoiseOptions o;
  o.ceiling = false;
  const NoiseEstimate ref = estimate_noise(unit, o);
  for (double k : {1e-250, 1e-50, 1e250}) {
    SCOPED_TRACE("scale " + text(k));
    const NoiseEstimate n = estimate_noise(scaled(unit, k), o);
    for (int c = 0; c < 3; ++c) {
      EXPECT_TRUE(std::isfinite(n.sigma[std::size_t(c)]));
      EXPECT_NEAR(n.sigma[std::size_t(c)], ref.sigma[std::size_t(c)],
                  1e-9 + 1e-6 * ref.sigma[std::size_t(c)]);
    }
  }
}

// ---- K as binary64 (spec 4.8, BASE flags bit 1) -----------------------------------------------

using Bytes = std::vector<std::uint8_t>;

// Six Frank slices with peaked theta_h tables (base_coding_test's golden13_frank6) whose first
// slice is 1e-60 times as bright in channel B: every other K as any 1.3 file holds it, that one
// beyond binary32. (One K only: the viewer's test compares the file's values in float32.)
Model wide_k_model() {
  Model m = testing::make_model(testing::six_slices(), true, 2024);
  for (Slice& s : m.slices) {
    for (ChannelSlice& c : s.channel) {
      c.family = CopulaFamily::kFrank;
      c.theta = -c.scale / 100.0;
    }
  }
  m.slices[0].channel[2].scale *= 1e-60;
  return m;
}

Bytes encode13(const Model& m, const std::string& source = "") {
  ContainerSettings s = testing::coding_1_2();
  s.bits = 10;
  s.format = ContainerSettings::Format::kV13;
  s.metadata = ContainerSettings::Metadata::kShort;
  s.source_name = source;
  Expected<Bytes> b = encode_model(m, s);
  EXPECT_TRUE(b.ok()) << b.status().message();
  return b.ok() ? *b : Bytes{};
}

Bytes base_payload(const Bytes& file) {
  Expected<ParsedContainer> pc = parse_container(file);
  EXPECT_TRUE(pc.ok());
  if (!pc.ok() || pc->find(kTagBase) < 0) return {};
  return pc->payloads[std::size_t(pc->find(kTagBase))];
}

Bytes with_base(const Bytes& file, const Bytes& base) {
  Expected<ParsedContainer> pc = parse_container(file);
  EXPECT_TRUE(pc.ok());
  std::vector<ChunkToWrite> chunks;
  for (std::size_t i = 0; i + 1 < pc->layout.chunks.size(); ++i) {
    const bool is_base = pc->layout.chunks[i].tag == kTagBase;
    chunks.push_back({pc->layout.chunks[i].tag, is_base ? base : pc->payloads[i], false});
  }
  Expected<Bytes> out = write_container(chunks, 3, 3);
  EXPECT_TRUE(out.ok()) << out.status().message();
  return out.ok() ? *out : Bytes{};
}

// Every K decodes to the model's K bit for bit, every parameter to its binary32.
void expect_exact_scales(const Model& built, const Model& decoded) {
  ASSERT_EQ(built.slices.size(), decoded.slices.size());
  for (std::size_t s = 0; s < built.slices.size(); ++s) {
    for (std::size_t c = 0; c < kChannels; ++c) {
      const ChannelSlice &a = built.slices[s].channel[c], &b = decoded.slices[s].channel[c];
      ASSERT_EQ(a.components(), b.components());
      for (int k = 0; k < a.components(); ++k) {
        EXPECT_EQ(b.component(k).scale, a.component(k).scale) << s << " " << c << " " << k;
        EXPECT_EQ(b.component(k).theta, double(float(a.component(k).theta)));
      }
    }
  }
}

using testing::model_hash;

constexpr const char* kWideGolden = "v1.3-wide-k-frank6-b10.cbrdf";
constexpr std::uint64_t kWideGoldenHash = 0x8469a364737ed475ull;

// CBRDF_REGENERATE_GOLDEN=v1.3-wide-k-frank6-b10.cbrdf (or all) rewrites the file and prints the
// hash to record above. The committed file decodes to the recorded model forever; the writer
// must still choose binary64 K for this model and keep every K exact.
TEST(ScaleRangeGolden, WideScaleFileDecodesToTheRecordedModel) {
  const std::filesystem::path path =
      std::filesystem::path(CBRDF_TEST_DATA_DIR) / "golden" / kWideGolden;
  const char* which = std::getenv("CBRDF_REGENERATE_GOLDEN");
  const Model built = wide_k_model();
  const Bytes fresh = encode13(built, kWideGolden);
  if (which != nullptr && (std::string(which) == "all" || std::string(which) == kWideGolden)) {
    std::ofstream(path, std::ios::binary)
        .write(reinterpret_cast<const char*>(fresh.data()), std::streamsize(fresh.size()));
  }
  std::ifstream in(path, std::ios::binary);
  const Bytes bytes{std::istreambuf_iterator<char>(in), {}};
  ASSERT_FALSE(bytes.empty()) << "missing golden file " << path;
  for (const Bytes* f : {&bytes, &fresh}) {
    ContainerInfo info;
    Expected<Model> decoded = decode_model(*f, &info);
    ASSERT_TRUE(decoded.ok()) << decoded.status().message();
    EXPECT_EQ(info.layout.minor, 3);
    EXPECT_EQ(base_payload(*f).at(1), kBaseFlagWideScales);
    expect_exact_scales(built, *decoded);
  }
  const std::uint64_t h = model_hash(decode_model(bytes).value());
  if (which != nullptr) std::printf("%s 0x%016llxull\n", kWideGolden, (unsigned long long)h);
  EXPECT_EQ(h, kWideGoldenHash) << std::hex << "decoded hash 0x" << h
                                << ": the format or the decoder changed";
}

// Only a K binary32 cannot keep sets the flag: files of ordinary tables keep their bytes. With
// mixtures both flags are set, and K at binary32's edges is handled either way.
TEST(ScaleRange, BinarySixtyFourKOnlyWhereNeeded) {
  Model plain = wide_k_model();
  plain.slices[0].channel[2].scale *= 1e60;
  EXPECT_EQ(base_payload(encode13(plain)).at(1), 0);
  for (double k : {1e-45, 1e-39, 1e39, 1e250}) {
    SCOPED_TRACE(text(k));
    Model m = testing::make_mixture_model({0, 20, 50, 90}, 4, 31);
    for (Slice& s : m.slices) {
      for (ChannelSlice& c : s.channel) {
        for (int j = 0; j < c.components(); ++j) c.component(j).scale *= k;
      }
    }
    ASSERT_TRUE(has_mixtures(m));
    const Bytes f = encode13(m);
    EXPECT_EQ(base_payload(f).at(1), kBaseFlagComponents | kBaseFlagWideScales);
    Expected<Model> d = decode_model(f);
    ASSERT_TRUE(d.ok()) << d.status().message();
    expect_exact_scales(m, *d);
  }
  EXPECT_TRUE(scale_fits_f32(0.0));
  EXPECT_TRUE(scale_fits_f32(0x1p-126));
  EXPECT_FALSE(scale_fits_f32(0x1p-127));
  EXPECT_TRUE(scale_fits_f32(3.4e38));
  EXPECT_FALSE(scale_fits_f32(3.5e38));
}

// A binary64 K follows 4.2's rules: finite and >= 0 (kNumeric), and present (kTruncated).
TEST(ScaleRange, BinarySixtyFourKIsChecked) {
  const Bytes f = encode13(wide_k_model());
  const Bytes base = base_payload(f);
  ASSERT_EQ(base.at(1), kBaseFlagWideScales);
  // The first record at 2 + 6 slice ends: family, f32 theta (9-12), f64 K (13-20).
  auto with_k = [&](double k) {
    Bytes b = base;
    const std::uint64_t bits = std::bit_cast<std::uint64_t>(k);
    for (int i = 0; i < 8; ++i) b[13 + std::size_t(i)] = std::uint8_t(bits >> (8 * i));
    return with_base(f, b);
  };
  ASSERT_TRUE(decode_model(with_k(1e-300)).ok());
  for (double k : {-1e-300, std::numeric_limits<double>::infinity(),
                   std::numeric_limits<double>::quiet_NaN()}) {
    testing::expect_refused(with_k(k), ErrorCode::kNumeric, "is not a finite value >= 0",
                            "slice 0 channel R");
  }
  testing::expect_refused(with_base(f, Bytes(base.begin(), base.begin() + 17)),
                          ErrorCode::kTruncated, "scale K");
}

}  // namespace
}  // namespace cbrdf
