// SPDX-License-Identifier: MIT
// The residual layer (container 1.2, 'RESD'): the --max-error bound on every measured bin of
// synthetic and real tables, version and mode bytes, residual-free files unchanged, evaluation
// with the residual, and the option checks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <random>

#include "cbrdf/codec.h"
#include "cbrdf/container.h"
#include "cbrdf/encoder.h"
#include "cbrdf/encoder_options.h"
#include "cbrdf/merl_io.h"
#include "eval/interp_tables.h"
#include "residual_encode.h"
#include "synthetic_model.h"
#include "table_builder.h"
#include "test_support.h"

namespace cbrdf {
namespace {

// A lobe over a diffuse floor with deterministic multiplicative noise (which the copula model
// cannot represent, so the residual has work everywhere) and some exact zeros.
BrdfTable noisy_table(std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  return testing::make_table([&](int c, int h, int d, int p) {
    const double lobe = 40.0 * std::exp(-double(h) / 6.0) * std::exp(-double(d) / 30.0);
    const double v = (0.05 + 0.02 * c + lobe) * (1.0 + 0.08 * u(rng)) * (1.0 + 0.001 * p);
    return (h * 7 + d * 3 + p) % 97 == 0 ? 0.0 : v;
  });
}

EncoderSettings settings_for(double max_error) {
  EncoderOptions o;
  o.slices = "2";
  o.bits = "10";
  o.zstd_level = 3;
  o.max_error = max_error;
  // The 1.0-1.2 coding, whose chunks these tests compare payload for payload (the 1.3 coding of a
  // residual file is covered by base_coding_test's golden file and the command's tests).
  o.format_version = "1.2";
  Expected<EncoderSettings> st = encoder_settings(o);
  EXPECT_TRUE(st.ok()) << st.status().message();
  return *st;
}

// Independent of the encoder's own check: |log1p(decoded) - log1p(source)| with stored values
// on measured bins, and not-measured bins bit for bit.
double checked_max_error(const BrdfTable& src, const BrdfTable& dec, double knee = 1e-4) {
  double worst = 0;
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      const double s = src.stored(c, i), d = dec.stored(c, i);
      if (!(s >= 0.0)) {
        EXPECT_EQ(std::memcmp(&s, &d, sizeof s), 0) << "not-measured bin " << i;
        continue;
      }
      const double e = std::abs(std::log1p(d / knee) - std::log1p(s / knee));
      EXPECT_TRUE(d >= 0.0 && std::isfinite(d)) << "channel " << c << " bin " << i << ": " << d;
      if (!(e <= worst)) worst = e;
    }
  }
  return worst;
}

std::vector<std::uint8_t> payload_of(const std::vector<std::uint8_t>& file, std::string_view tag) {
  Expected<ParsedContainer> pc = parse_container(file);
  EXPECT_TRUE(pc.ok()) << pc.status().message();
  if (!pc.ok() || pc->find(tag) < 0) return {};
  return pc->payloads[std::size_t(pc->find(tag))];
}

struct Encoded {
  BrdfTable source;
  EncodeResult result;
};

const Encoded& encoded_at(double max_error) {
  static std::map<double, Encoded> cache;
  auto it = cache.find(max_error);
  if (it == cache.end()) {
    Encoded e{noisy_table(7), {}};
    Expected<EncodeResult> r = encode_table(e.source, settings_for(max_error));
    EXPECT_TRUE(r.ok()) << r.status().message();
    if (r.ok()) e.result = std::move(r).value();
    it = cache.emplace(max_error, std::move(e)).first;
  }
  return it->second;
}

TEST(Residual, BoundHeldOnEveryMeasuredBinOfASyntheticTable) {
  for (double e : {0.05, 0.002}) {
    SCOPED_TRACE(e);
    const Encoded& enc = encoded_at(e);
    ASSERT_FALSE(enc.result.bytes.empty());
    Expected<BrdfTable> dec = decode_table(enc.result.bytes);
    ASSERT_TRUE(dec.ok()) << dec.status().message();
    const double worst = checked_max_error(enc.source, *dec);
    EXPECT_LE(worst, e);
    // The quantizer uses its step: the worst bin comes close to the bound (rounding to a step
    // just under 2E), so the layer is not finer than asked.
    EXPECT_GT(worst, 0.9 * e);
    // Version 1.2, mode 0, a predictor (0 or 1), the bound recorded.
    EXPECT_EQ(enc.result.bytes[10], 2);
    EXPECT_EQ(enc.result.bytes[11], 0);
    const std::vector<std::uint8_t> p = payload_of(enc.result.bytes, kTagResidual);
    ASSERT_GE(p.size(), 24u);
    EXPECT_EQ(p[0], 0);
    EXPECT_LE(p[1], 1);
    Expected<ContainerInfo> info = inspect_container(enc.result.bytes);
    ASSERT_TRUE(info.ok());
    EXPECT_EQ(info->residual_mode, 0);
    EXPECT_EQ(info->residual_max_error, e);
  }
  // A tighter bound costs more bytes.
  EXPECT_GT(encoded_at(0.002).result.bytes.size(), encoded_at(0.05).result.bytes.size());
}

TEST(Residual, FilesWithoutAResidualAreWrittenAsBefore) {
  const Encoded& enc = encoded_at(0.05);
  EncoderSettings st = settings_for(0);
  // The same fitted model without the layer: version 1.0, no RESD, and the bytes encode_model
  // writes for it (the 1.0 writer's). (2 slices x 3 channels: 6 further-component counts.)
  Model base = enc.result.model;
  base.residual = Residual{};
  Expected<std::vector<std::uint8_t>> plain = encode_model(base, st.container);
  ASSERT_TRUE(plain.ok());
  EXPECT_EQ((*plain)[10], 0);
  EXPECT_TRUE(payload_of(*plain, kTagResidual).empty());
  // The residual file's other chunks are the plain file's, payload for payload, except that MODL
  // of a 1.2 file holds the further-component counts (all 0: one per slice and channel).
  for (std::string_view tag : {kTagHeader, kTagMarginals, kTagMask}) {
    EXPECT_EQ(payload_of(*plain, tag), payload_of(enc.result.bytes, tag)) << tag;
  }
  std::vector<std::uint8_t> modl = payload_of(*plain, kTagModel);
  modl.resize(modl.size() + 2 * kChannels, 0);
  EXPECT_EQ(modl, payload_of(enc.result.bytes, kTagModel));
}

// Direction pair at the centre of a MERL bin.
void bin_directions(int h, int d, int p, Vec3* wi, Vec3* wo) {
  HalfDiff hd;
  hd.theta_h = theta_h_of(h);
  hd.theta_d = theta_d_of(d);
  hd.phi_d = phi_d_of(p);
  from_half_diff(hd, wi, wo);
}

TEST(Residual, EvaluationIncludesTheResidualAndResidualFreeModelsAreUnchanged) {
  const Encoded& enc = encoded_at(0.002);
  Expected<Model> model = decode_model(enc.result.bytes);
  ASSERT_TRUE(model.ok());
  ASSERT_TRUE(model->residual.present());
  const BrdfTable table = model->table();
  const ModelEvaluator ev(*model);
  Model base = *model;
  base.residual = Residual{};
  const ModelEvaluator base_ev(base);
  const internal::InterpTables interp(base);
  std::vector<double> wi, wo;
  int checked = 0;
  for (int h = 5; h < 90; h += 13) {
    for (int d = 1; d < 88; d += 11) {
      for (int p = 3; p < 180; p += 17) {
        Vec3 a, b;
        bin_directions(h, d, p, &a, &b);
        if (a.z <= 0.05 || b.z <= 0.05) continue;
        double rgb[3], base_rgb[3], interp_rgb[3];
        ev.eval(a, b, rgb);
        base_ev.eval(a, b, base_rgb);
        interp.eval(a, b, interp_rgb);
        for (int c = 0; c < kChannels; ++c) {
          // At a bin centre: the decoded table's value (up to the interpolation's rounding).
          const double want = table.physical(c, merl_index(h, d, p));
          EXPECT_NEAR(rgb[c], want, 1e-6 * want + 1e-12) << h << " " << d << " " << p;
          // Without a residual, the evaluator is the base interpolation, bit for bit.
          EXPECT_EQ(std::memcmp(&base_rgb[c], &interp_rgb[c], sizeof(double)), 0);
        }
        wi.insert(wi.end(), {a.x, a.y, a.z});
        wo.insert(wo.end(), {b.x, b.y, b.z});
        ++checked;
      }
    }
  }
  ASSERT_GT(checked, 100);
  // The batch path equals eval pair by pair, residual included.
  std::vector<double> rgb(wi.size());
  ev.eval_batch(std::size_t(checked), wi.data(), wo.data(), rgb.data());
  for (int k = 0; k < checked; ++k) {
    double one[3];
    ev.eval(Vec3{wi[3 * k], wi[3 * k + 1], wi[3 * k + 2]},
            Vec3{wo[3 * k], wo[3 * k + 1], wo[3 * k + 2]}, one);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(rgb[std::size_t(3 * k + c)], one[c]);
  }
  // Below the horizon: 0, as the base.
  double below[3] = {1, 1, 1};
  ev.eval(Vec3{0, 0.6, -0.8}, Vec3{0, 0, 1}, below);
  for (double v : below) EXPECT_EQ(v, 0.0);
}

TEST(Residual, OptionsAreCheckedWithOneLineMessages) {
  EncoderOptions o;
  o.max_error = 0.01;
  o.lossless = true;
  Expected<EncoderSettings> st = encoder_settings(o);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_TRUE(testing::contains(st.status().message(), "exclude each other"));
  for (double bad : {-1.0, 1e-9, 17.0, std::nan("")}) {
    o = EncoderOptions{};
    o.max_error = bad;
    st = encoder_settings(o);
    ASSERT_FALSE(st.ok()) << bad;
    EXPECT_TRUE(
        testing::contains(st.status().message(), "max_error must be from 1e-06 to 16, not "))
        << st.status().message();
  }
  const testing::CommandResult r =
      testing::run_cli("encode x.binary -o y.cbrdf --max-error 0.1 --lossless");
  EXPECT_EQ(r.exit_code, 2);
}

// Continuous evaluation at the centres of bins with phi_d bin p, over a spread of theta_h and
// theta_d away from the horizon: the decoded table's values.
void expect_bin_centres_are_the_table(const Model& model, const BrdfTable& dec, int p) {
  const ModelEvaluator ev(model);
  int checked = 0;
  for (int h = 3; h < 90; h += 7) {
    for (int d = 2; d < 88; d += 9) {
      Vec3 a, b;
      bin_directions(h, d, p, &a, &b);
      if (a.z <= 0.05 || b.z <= 0.05) continue;
      double rgb[3];
      ev.eval(a, b, rgb);
      for (int c = 0; c < kChannels; ++c) {
        const double want = dec.physical(c, merl_index(h, d, p));
        EXPECT_NEAR(rgb[c], want, 1e-6 * want + 1e-12) << h << " " << d;
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 50);
}

// RESD mode 2 (ResidualSettings::row_steps): each row's bound held on every measured bin, checked
// here from the row shifts the file stores; coarser rows cost fewer bytes than one bound; the
// evaluator applies each bin's row step.
TEST(Residual, RowStepsHoldEachRowsBound) {
  const Encoded& uniform = encoded_at(0.002);
  EncoderSettings st = settings_for(0.002);
  st.residual.row_steps = true;
  Expected<EncodeResult> r = encode_table(uniform.source, st);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(payload_of(r->bytes, kTagResidual)[0], 2);
  Expected<Model> model = decode_model(r->bytes);
  ASSERT_TRUE(model.ok()) << model.status().message();
  const std::vector<std::uint8_t>& shift = model->residual.row_shift;
  ASSERT_EQ(shift.size(), 8100u);
  EXPECT_EQ(shift, internal::residual_row_shifts(0.002));
  const BrdfTable dec = model->table();
  double worst_fine = 0, worst_ratio = 0;
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      const double s = uniform.source.stored(c, i);
      if (!(s >= 0.0)) continue;
      const double e = std::abs(std::log1p(dec.stored(c, i) / 1e-4) - std::log1p(s / 1e-4));
      const double bound = std::ldexp(0.002, shift[i / 180]);
      ASSERT_LE(e, bound) << c << " " << i;
      if (shift[i / 180] == 0) worst_fine = std::max(worst_fine, e);
      worst_ratio = std::max(worst_ratio, e / 0.002);
    }
  }
  EXPECT_GT(worst_fine, 0.9 * 0.002);  // the finest rows use their step
  EXPECT_GT(worst_ratio, 8.0);         // and coarse rows theirs
  EXPECT_LT(r->bytes.size(), uniform.result.bytes.size());
  Expected<ContainerInfo> info = inspect_container(r->bytes);
  ASSERT_TRUE(info.ok());
  EXPECT_EQ(info->residual_mode, 2);
  EXPECT_EQ(info->residual_min_error, 0.002);
  EXPECT_EQ(info->residual_max_error, 0.002 * 64);
  // Continuous evaluation at bin centres: the decoded table.
  expect_bin_centres_are_the_table(*model, dec, 40);
}

// RESD mode 4 (target_residual_settings in a 1.3 file): every bin within its own bound (row
// shift, times its level's multiplier), checked from the fields the file stores; the reader
// rebuilds the writer's residual bit for bit; the finer levels use their wider bounds; evaluation
// at bin centres is the table. A 1.2 file takes mode 3.
TEST(Residual, InterpolatedLevelsHoldEachBinsBound) {
  const Encoded& uniform = encoded_at(0.002);
  EncoderSettings st = settings_for(0.002);
  st.residual = target_residual_settings(0.002);
  st.container.format = ContainerSettings::Format::kAuto;  // settings_for's is 1.2
  Expected<EncodeResult> r = encode_table(uniform.source, st);
  ASSERT_TRUE(r.ok()) << r.status().message();
  // A 1.3 file: mode 4, the finest level 32 times its row's bound and level 1 8 times.
  EXPECT_EQ(r->bytes[10], 3);
  EXPECT_EQ(payload_of(r->bytes, kTagResidual)[0], 4);
  Expected<Model> model = decode_model(r->bytes);
  ASSERT_TRUE(model.ok()) << model.status().message();
  const Residual& res = model->residual;
  ASSERT_EQ(res.levels, 3);
  ASSERT_EQ(res.fine_multiplier, 32);
  ASSERT_EQ(res.middle_multipliers, (std::array<std::uint8_t, 3>{8, 1, 1}));
  EXPECT_EQ(res.row_shift, internal::residual_row_shifts(0.002, 32));
  EXPECT_EQ(res.values, r->model.residual.values);
  const BrdfTable dec = model->table();
  // Per level (0 the finest, 3 the coarsest nodes): the largest error over the row's bound.
  const double multiplier[4] = {32, 8, 1, 1};
  double worst[4] = {0, 0, 0, 0};
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      const double s = uniform.source.stored(c, i);
      if (!(s >= 0.0)) continue;
      const double e = std::abs(std::log1p(dec.stored(c, i) / 1e-4) - std::log1p(s / 1e-4));
      const double row = std::ldexp(0.002, res.row_shift[i / 180]);
      // The level from the indices, as spec 4.6 defines it: min(tz(theta_d), tz(phi_d), 3).
      const std::size_t both = (i % 180) | ((i / 180) % 90);
      const int level = (both & 1) ? 0 : (both & 2) ? 1 : (both & 4) ? 2 : 3;
      ASSERT_LE(e, multiplier[level] * row) << c << " " << i;
      worst[level] = std::max(worst[level], e / row);
    }
  }
  EXPECT_GT(worst[0], 24.0);  // the finest level uses its multiplier
  EXPECT_GT(worst[1], 6.0);   // and level 1 its own
  EXPECT_GT(worst[2], 0.9);   // the coarser ones their row's step
  EXPECT_GT(worst[3], 0.9);
  Expected<ContainerInfo> info = inspect_container(r->bytes);
  ASSERT_TRUE(info.ok());
  EXPECT_EQ(info->residual_mode, 4);
  EXPECT_EQ(info->residual_min_error, 0.002);
  EXPECT_EQ(info->residual_max_error, 0.002 * 32 * (1 << res.max_row_shift()));
  expect_bin_centres_are_the_table(*model, dec, 41);  // an odd phi_d: the finest level

  // In a 1.2 file the same settings write mode 3: the finest level alone coarser, at mode 3's
  // multiplier 8.
  st.container.format = ContainerSettings::Format::kV12;
  Expected<EncodeResult> old = encode_table(uniform.source, st);
  ASSERT_TRUE(old.ok()) << old.status().message();
  EXPECT_EQ(old->bytes[10], 2);
  EXPECT_EQ(payload_of(old->bytes, kTagResidual)[0], 3);
  Expected<Model> old_model = decode_model(old->bytes);
  ASSERT_TRUE(old_model.ok()) << old_model.status().message();
  EXPECT_EQ(st.residual.mode3_fine_multiplier, 8);
  EXPECT_EQ(old_model->residual.fine_multiplier, 8);
  EXPECT_EQ(old_model->residual.middle_multipliers, (std::array<std::uint8_t, 3>{1, 1, 1}));
  EXPECT_EQ(old_model->residual.row_shift, internal::residual_row_shifts(0.002, 8));
  // Without mode 3's own multiplier a 1.2 file takes the finest one.
  st.residual.mode3_fine_multiplier = 0;
  Expected<EncodeResult> plain = encode_table(uniform.source, st);
  ASSERT_TRUE(plain.ok()) << plain.status().message();
  EXPECT_EQ(decode_model(plain->bytes)->residual.fine_multiplier, 32);
}

// Multipliers outside the format's 1..64 are the caller's error, named in the message.
TEST(Residual, OutOfRangeMultipliersAreRefused) {
  const Encoded& uniform = encoded_at(0.002);
  for (int which = 0; which < 3; ++which) {
    EncoderSettings st = settings_for(0.002);
    st.residual = target_residual_settings(0.002);
    if (which == 0) st.residual.fine_multiplier = 65;
    if (which == 1) st.residual.middle_multipliers[1] = 0;
    if (which == 2) st.residual.mode3_fine_multiplier = 65;
    EncodeResult r = uniform.result;
    const Status s = internal::add_residual(uniform.source, st, &r);
    ASSERT_EQ(s.code(), ErrorCode::kInvalidArgument) << which;
    EXPECT_NE(s.message().find("each multiplier 1..64"), std::string::npos) << s.message();
    EXPECT_NE(s.message().find(which == 2 ? "(65 in mode 3)" : "residual levels 3"),
              std::string::npos)
        << s.message();
  }
}

// Where the residual is smooth, mode 3's codes are mostly 0: on a smooth residual over a fixed
// base the file is several times smaller than mode 2's at the same row bounds.
TEST(Residual, InterpolatedLevelsCostLittleOnASmoothResidual) {
  EncodeResult base;
  base.model = testing::make_model({0, 90}, true, 5);
  const BrdfTable base_table = base.model.table();
  // The base times a smooth factor: the residual is a smooth function of the bin.
  BrdfTable src = base_table;
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      const BinIndex b = merl_bin(i);
      if (src.stored(c, i) >= 0.0) {
        src.set_stored(c, i,
                       src.stored(c, i) * (1.2 + 0.3 * std::sin(0.05 * b.theta_d) *
                                                     std::cos(0.03 * b.phi_d + 0.02 * b.theta_h)));
      }
    }
  }
  EncoderSettings st = settings_for(0.002);
  Expected<std::vector<std::uint8_t>> base_bytes = encode_model(base.model, st.container);
  ASSERT_TRUE(base_bytes.ok());
  base.bytes = *base_bytes;
  base.bits = st.container.bits;
  std::size_t sizes[2] = {};
  for (int interp = 0; interp < 2; ++interp) {
    st.residual = target_residual_settings(0.002);
    if (interp == 0) st.residual.levels = 0;
    EncodeResult r = base;
    ASSERT_TRUE(internal::add_residual(src, st, &r).ok());
    Expected<BrdfTable> dec = decode_table(r.bytes);
    ASSERT_TRUE(dec.ok());
    EXPECT_LE(checked_max_error(src, *dec), 0.002 * 8 * 64);
    sizes[interp] = r.bytes.size() - base.bytes.size();
  }
  EXPECT_LT(3 * sizes[1], sizes[0]) << sizes[1] << " against mode 2's " << sizes[0];
}

// The shifts: 0 on the most visible rows, the cap where cos(theta_i) cos(theta_o) vanishes, and
// never a row bound above the format's 16.
TEST(Residual, RowShiftsFollowTheRowsWeight) {
  const std::vector<std::uint8_t> s = internal::residual_row_shifts(0.01);
  ASSERT_EQ(s.size(), 8100u);
  EXPECT_EQ(*std::min_element(s.begin(), s.end()), 0);
  EXPECT_EQ(*std::max_element(s.begin(), s.end()), internal::kRowStepShiftCap);
  EXPECT_EQ(s[89 * 90 + 89], internal::kRowStepShiftCap);  // grazing: nothing seen
  // Near-normal incidence and reflection count more than theta_d near 90 at the same theta_h.
  EXPECT_LT(s[30 * 90 + 10], s[30 * 90 + 85]);
  const std::vector<std::uint8_t> big = internal::residual_row_shifts(4.0);
  EXPECT_EQ(*std::max_element(big.begin(), big.end()), 2);  // 4 x 2^2 = 16
}

// The bound on every real material (../shared). The base is one fixed synthetic model rather
// than a fit (which would cost seconds per material): the bound must hold whatever the base, and
// a poor one makes the residual large, which exercises the codes' range.
TEST(Residual, BoundHeldOnEveryRealMaterial) {
  const std::vector<std::string> names = testing::real_material_names();
  if (names.empty()) GTEST_SKIP() << "no real materials (../shared/data is absent)";
  EncodeResult base;
  base.model = testing::make_model({0, 90}, true, 5);
  // Independence: the cheapest base to evaluate (this test checks the layer, not the model).
  for (ChannelSlice& cs : base.model.slices[0].channel) {
    cs.family = CopulaFamily::kIndependence;
    cs.theta = 0;
  }
  EncoderSettings st = settings_for(0.01);
  st.container.bits = 8;
  st.container.zstd_level = 1;
  for (const std::string& name : names) {
    SCOPED_TRACE(name);
    Expected<BrdfTable> src = read_merl(testing::real_materials_dir() / (name + ".binary"));
    ASSERT_TRUE(src.ok()) << src.status().message();
    EncodeResult r = base;
    r.model.not_measured = NotMeasured::from_table(*src);
    Expected<std::vector<std::uint8_t>> base_bytes = encode_model(r.model, st.container);
    ASSERT_TRUE(base_bytes.ok()) << base_bytes.status().message();
    r.bytes = *base_bytes;
    r.bits = 8;
    ASSERT_TRUE(internal::add_residual(*src, st, &r).ok());
    Expected<BrdfTable> dec = decode_table(r.bytes);
    ASSERT_TRUE(dec.ok()) << dec.status().message();
    EXPECT_LE(checked_max_error(*src, *dec), 0.01);
  }
}

}  // namespace
}  // namespace cbrdf
