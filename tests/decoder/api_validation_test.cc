// SPDX-License-Identifier: MIT
// The C++ API refuses what it cannot evaluate and survives what a renderer does with it (issue 25):
// invalid directions give NaN (never a BRDF value), eval and eval_f32 agree on them, directions
// within the tolerance are rescaled, a sampler outlives a moved evaluator, small sample batches
// equal large ones draw for draw, decode_model_file reads a file and names an empty path.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "bitstream/chunks.h"
#include "cbrdf/cbrdf_cxx.h"
#include "cbrdf/codec.h"
#include "cbrdf/model.h"
#include "cbrdf/sampling.h"
#include "synthetic_model.h"

namespace cbrdf {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool all_nan(const double rgb[3]) {
  return std::isnan(rgb[0]) && std::isnan(rgb[1]) && std::isnan(rgb[2]);
}

TEST(ApiValidation, EvalOfAnInvalidDirectionIsNaN) {
  const ModelEvaluator& e = testing::peaked_evaluator();
  const Vec3 wo = testing::direction_deg(0, 0);
  double rgb[3];
  // Before: {NaN, 0, 1} at the normal returned the peak value.
  for (const Vec3& bad :
       {Vec3{kNaN, 0, 1}, Vec3{0, 0, kNaN}, Vec3{1e300, 0, 1e300}, Vec3{0, 0, 1e-3}, Vec3{0, 0, 2},
        Vec3{0, std::numeric_limits<double>::infinity(), 1}}) {
    e.eval(bad, wo, rgb);
    EXPECT_TRUE(all_nan(rgb)) << bad.x << " " << bad.y << " " << bad.z << ": " << rgb[0];
    e.eval(wo, bad, rgb);
    EXPECT_TRUE(all_nan(rgb));
  }
  // A valid pair still evaluates.
  e.eval(wo, wo, rgb);
  EXPECT_TRUE(std::isfinite(rgb[1]) && rgb[1] > 0);
}

TEST(ApiValidation, EvalAndEvalF32AgreeOnInvalidInput) {
  const ModelEvaluator& e = testing::peaked_evaluator();
  // Before: 0.0028 (double) against 6.47 (float, where 1e300 is +Inf).
  const Vec3 bad{1e300, 0, 1e300}, wo = testing::direction_deg(30, 180);
  const float badf[3] = {float(bad.x), float(bad.y), float(bad.z)};
  const float wof[3] = {float(wo.x), float(wo.y), float(wo.z)};
  double rgb[3];
  float rgbf[3];
  e.eval(bad, wo, rgb);
  e.eval_f32(badf, wof, rgbf);
  for (int c = 0; c < 3; ++c) {
    EXPECT_TRUE(std::isnan(rgb[c]));
    EXPECT_TRUE(std::isnan(rgbf[c]));
  }
  // The batch forms mark the same pair NaN and evaluate the others as eval does.
  const Vec3 wi = testing::direction_deg(30, 0);
  const double in_i[6] = {wi.x, wi.y, wi.z, bad.x, bad.y, bad.z};
  const double in_o[6] = {wo.x, wo.y, wo.z, wo.x, wo.y, wo.z};
  double out[6], ref[3];
  e.eval_batch(2, in_i, in_o, out);
  e.eval(wi, wo, ref);
  EXPECT_EQ(std::memcmp(out, ref, sizeof ref), 0);
  EXPECT_TRUE(all_nan(out + 3));
  const float fi[6] = {float(wi.x), float(wi.y), float(wi.z), badf[0], badf[1], badf[2]};
  const float fo[6] = {wof[0], wof[1], wof[2], wof[0], wof[1], wof[2]};
  float outf[6], reff[3];
  e.eval_batch_f32(2, fi, fo, outf);
  e.eval_f32(fi, fo, reff);
  EXPECT_EQ(std::memcmp(outf, reff, sizeof reff), 0);
  EXPECT_TRUE(std::isnan(outf[3]) && std::isnan(outf[4]) && std::isnan(outf[5]));
}

TEST(ApiValidation, DirectionsWithinTheToleranceAreRescaled) {
  const ModelEvaluator& e = testing::peaked_evaluator();
  const Vec3 wi = testing::direction_deg(30, 0),
             wo = testing::direction_deg(30, 180);  // the mirror direction
  const Vec3 wi_long{wi.x * 1.0004, wi.y * 1.0004, wi.z * 1.0004};
  const Vec3 wo_short{wo.x * 0.9997, wo.y * 0.9997, wo.z * 0.9997};
  double unit[3], scaled[3];
  e.eval(wi, wo, unit);
  e.eval(wi_long, wo_short, scaled);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(scaled[c], unit[c], 1e-12 * unit[c]);
  // A unit vector keeps its bits: the value is exactly the one at the vector as given.
  Vec3 w = wi;
  EXPECT_TRUE(unit_direction(w));
  EXPECT_EQ(std::memcmp(&w, &wi, sizeof w), 0);
  // The sampler's density too (before: NaN gave 0.0297, and a long vector its own value).
  const BrdfSampler s = make_model_sampler(e);
  EXPECT_NEAR(s.sample_pdf(wi_long, wo_short), s.sample_pdf(wi, wo), 1e-12 * s.sample_pdf(wi, wo));
  EXPECT_TRUE(std::isnan(s.sample_pdf(Vec3{kNaN, 0, 1}, wo)));
  EXPECT_TRUE(std::isnan(s.sample_pdf(wi, Vec3{0, 0, 5})));
  EXPECT_FALSE(s.sample(Vec3{kNaN, 0, 1}, 0.5, 0.5).valid);
}

TEST(ApiValidation, SamplerOutlivesAMovedEvaluator) {
  // Before: the sampler pointed at the evaluator; moving it away crashed the next draw.
  ModelEvaluator e(testing::make_model(testing::six_slices(), /*peaked=*/true));
  const Vec3 wo = testing::direction_deg(40, 70);
  const BrdfSampler sampler = make_model_sampler(e);
  const BrdfFn f = model_brdf_fn(e);
  BrdfSample before[16];
  for (int k = 0; k < 16; ++k) before[k] = sampler.sample(wo, (k + 0.5) / 16, 0.3);
  ModelEvaluator moved = std::move(e);
  e = ModelEvaluator(testing::make_model(testing::six_slices(), /*peaked=*/false));  // reused
  int valid = 0;
  for (int k = 0; k < 16; ++k) {
    double w[3];
    const BrdfSample s = sampler.sample(wo, (k + 0.5) / 16, 0.3, w);
    EXPECT_EQ(s.valid, before[k].valid);
    if (!s.valid) continue;
    ++valid;
    EXPECT_EQ(s.pdf, before[k].pdf);
    double rgb[3], ref[3];
    f(s.wi, wo, rgb);
    moved.eval(s.wi, wo, ref);
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(rgb[c], ref[c]);
      EXPECT_EQ(w[c], ref[c] * s.wi.z / s.pdf);
    }
  }
  EXPECT_GT(valid, 8);
  // Copies share the prepared tables and evaluate identically.
  const ModelEvaluator copy = moved;
  double a[3], b[3];
  copy.eval(testing::direction_deg(20, 0), wo, a);
  moved.eval(testing::direction_deg(20, 0), wo, b);
  EXPECT_EQ(std::memcmp(a, b, sizeof a), 0);
}

TEST(ApiValidation, SmallSampleBatchesEqualLargeOnes) {
  const ModelEvaluator& e = testing::peaked_evaluator();
  const BrdfSampler s = make_model_sampler(e);
  constexpr std::size_t kN = 300;
  std::vector<double> wo(3 * kN), u(2 * kN), wi(3 * kN), pdf(kN), weight(3 * kN);
  for (std::size_t k = 0; k < kN; ++k) {
    // Some wo below the horizon, some invalid, some off unit length within the tolerance.
    const Vec3 w =
        testing::direction_deg(k % 13 == 0 ? 100.0 : double(k % 89), double(k * 37 % 360));
    const double scale = k % 7 == 0 ? 1.0003 : 1.0;
    wo[3 * k] = w.x * scale;
    wo[3 * k + 1] = w.y * scale;
    wo[3 * k + 2] = k % 29 == 0 ? kNaN : w.z * scale;
    u[2 * k] = std::fmod(k * 0.6180339887, 1.0);
    u[2 * k + 1] = std::fmod(k * 0.7548776662, 1.0);
  }
  s.sample_batch(kN, wo.data(), u.data(), wi.data(), pdf.data(), weight.data(), 1);
  int rejected = 0;
  for (std::size_t k = 0; k < kN; ++k) {
    // One draw at a time, through the batch of 1 and sample() with weights.
    double wi1[3], pdf1, w1[3], w2[3];
    s.sample_batch(1, &wo[3 * k], &u[2 * k], wi1, &pdf1, w1, 1);
    EXPECT_EQ(std::memcmp(wi1, &wi[3 * k], sizeof wi1), 0) << k;
    EXPECT_EQ(std::memcmp(&pdf1, &pdf[k], sizeof pdf1), 0) << k;
    EXPECT_EQ(std::memcmp(w1, &weight[3 * k], sizeof w1), 0) << k;
    const BrdfSample one =
        s.sample(Vec3{wo[3 * k], wo[3 * k + 1], wo[3 * k + 2]}, u[2 * k], u[2 * k + 1], w2);
    EXPECT_EQ(std::memcmp(&one.wi, &wi[3 * k], sizeof wi1), 0) << k;
    EXPECT_EQ(one.pdf, pdf[k]);
    EXPECT_EQ(std::memcmp(w2, &weight[3 * k], sizeof w2), 0) << k;
    if (pdf[k] == 0) ++rejected;
  }
  EXPECT_GT(rejected, int(kN / 13));  // below the horizon and invalid wo
  for (std::size_t n : {2, 5, 9, 17, 130}) {
    std::vector<double> wi_n(3 * n), pdf_n(n), weight_n(3 * n);
    s.sample_batch(n, &wo[3 * 11], &u[2 * 11], wi_n.data(), pdf_n.data(), weight_n.data(), 1);
    EXPECT_EQ(std::memcmp(wi_n.data(), &wi[3 * 11], 3 * n * sizeof(double)), 0) << n;
    EXPECT_EQ(std::memcmp(weight_n.data(), &weight[3 * 11], 3 * n * sizeof(double)), 0) << n;
  }
}

TEST(ApiValidation, DirectionalAlbedoMatchesBruteForce) {
  // A fitted file (the synthetic models' peaks are too narrow for the brute force's grid).
  auto decoded =
      decode_model_file(std::string(CBRDF_TEST_DATA_DIR) + "/golden/v1.1-mixture3-b12.cbrdf");
  ASSERT_TRUE(decoded.ok()) << decoded.status().message();
  const ModelEvaluator e(std::move(decoded).value());
  for (double theta : {15.0, 60.0}) {
    const Vec3 wo = testing::direction_deg(theta, 0);
    double a[3];
    e.albedo(wo.z, a, 1);
    // Brute force over wi, uniform in cos(theta_i) and phi_i.
    double sum[3] = {0, 0, 0};
    constexpr int kT = 400, kP = 800;
    for (int i = 0; i < kT; ++i) {
      const double ct = 1 - (i + 0.5) / kT, st = std::sqrt(1 - ct * ct);
      std::vector<double> wi(3 * kP), wos(3 * kP), f(3 * kP);
      for (int j = 0; j < kP; ++j) {
        const double p = (j + 0.5) * 2 * std::numbers::pi / kP;
        wi[3 * j] = st * std::cos(p), wi[3 * j + 1] = st * std::sin(p), wi[3 * j + 2] = ct;
        wos[3 * j] = wo.x, wos[3 * j + 1] = wo.y, wos[3 * j + 2] = wo.z;
      }
      e.eval_batch(kP, wi.data(), wos.data(), f.data(), 1);
      for (int j = 0; j < kP; ++j) {
        for (int c = 0; c < 3; ++c) sum[c] += f[3 * j + c] * ct / kT * 2 * std::numbers::pi / kP;
      }
    }
    const double floor = 1e-3 * (sum[0] + sum[1] + sum[2]);  // a channel near 0
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(a[c], sum[c], 0.01 * sum[c] + floor) << theta << " " << c;
    }
  }
  double a[3];
  e.albedo(-0.2, a, 1);
  EXPECT_TRUE(a[0] == 0 && a[1] == 0 && a[2] == 0);
  e.albedo(kNaN, a, 1);
  EXPECT_TRUE(all_nan(a));
}

TEST(ApiValidation, DecodeModelFile) {
  const std::string path = std::string(CBRDF_TEST_DATA_DIR) + "/golden/v1.0-frank6-b10.cbrdf";
  ContainerInfo info;
  auto m = decode_model_file(path, &info);
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->slices.size(), 6u);
  EXPECT_EQ(info.layout.file_bytes, 3354u);
  auto empty = decode_model_file("");
  ASSERT_FALSE(empty.ok());
  EXPECT_EQ(empty.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(empty.status().message().find("empty"), std::string::npos);
  auto missing = decode_model_file(path + ".missing");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().code(), ErrorCode::kNotFound);
  EXPECT_NE(missing.status().message().find(".missing"), std::string::npos);
}

// The header-only RAII of the C handle frees what it holds and is null after a failed open.
TEST(ApiValidation, CxxWrapperOfTheCHandle) {
  const std::string path = std::string(CBRDF_TEST_DATA_DIR) + "/golden/v1.0-frank6-b10.cbrdf";
  abi::ModelPtr m = abi::open_model_file(path.c_str());
  ASSERT_TRUE(m != nullptr) << cbrdf_last_error_message();
  cbrdf_model_info info{};
  info.struct_size = sizeof info;
  ASSERT_EQ(cbrdf_model_get_info(m.get(), &info), CBRDF_OK);
  EXPECT_EQ(info.slices, 6);
  abi::ModelPtr missing = abi::open_model_file((path + ".missing").c_str());
  EXPECT_TRUE(missing == nullptr);
  EXPECT_EQ(cbrdf_last_error_code(), CBRDF_ERROR_NOT_FOUND);
}

// The decoder's below-horizon reference mask, built from per-axis sines and cosines (the first
// decode in a process used to spend 135 ms on it), is bin_below_horizon's bit for bit.
TEST(ApiValidation, BelowHorizonMaskIsTheGeometricOne) {
  const std::vector<std::uint64_t>& bits = below_horizon_bits();
  std::size_t differ = 0, set = 0;
  for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
    const BinIndex b = merl_bin(i);
    const bool want = bin_below_horizon(b.theta_h, b.theta_d, b.phi_d);
    const bool got = (bits[i >> 6] >> (i & 63)) & 1u;
    differ += want != got;
    set += got;
  }
  EXPECT_EQ(differ, 0u);
  EXPECT_GT(set, kBinsPerChannel / 10);
}

}  // namespace
}  // namespace cbrdf
