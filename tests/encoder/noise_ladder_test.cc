// SPDX-License-Identifier: MIT
// The ladder on noisy tables (issue 30): --target-psnr and --target-bytes stop at the noise floor
// with a note, and the residual codes the signal the model misses, not the noise: the file ends
// closer to the noise-free truth than the model alone. On a sample made noisy here, and on a real
// material made noisy at test time by ../shared/tools/make-merl.sh --noise 0.03.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "cbrdf/codec.h"
#include "cbrdf/encoder.h"
#include "cbrdf/merl_io.h"
#include "cbrdf/noise.h"
#include "cbrdf/rate_control.h"
#include "cbrdf/samples.h"
#include "coding_1_2.h"
#include "metrics.h"
#include "test_support.h"

namespace cbrdf {
namespace {

EncoderSettings settings() {
  EncoderSettings s = testing::encoder_1_2();
  s.fit.threads = 2;
  s.fit.slices = 6;
  return s;
}

double psnr(const BrdfTable& reference, const std::vector<std::uint8_t>& file) {
  auto decoded = decode_table(file);
  EXPECT_TRUE(decoded.ok()) << decoded.status().message();
  return decoded.ok() ? sphere_psnr(reference, *decoded).psnr_tonemapped : 0.0;
}

// What the issue asks of one noisy table: the model alone, the PSNR target far beyond the noise
// and a budget, each against the truth.
void check_ladder(const BrdfTable& truth, const BrdfTable& noisy, double min_gain_db,
                  double budget) {
  const EncoderSettings st = settings();
  auto model = encode_table(noisy, st);
  ASSERT_TRUE(model.ok()) << model.status().message();
  const double model_truth = psnr(truth, model->bytes);
  const double input_truth = sphere_psnr(truth, noisy).psnr_tonemapped;

  auto high = encode_to_target_ladder(noisy, st, {0, 60, 1, {6}});
  ASSERT_TRUE(high.ok()) << high.status().message();
  EXPECT_FALSE(high->met);
  EXPECT_NE(high->note.find("the input is noisy"), std::string::npos) << high->note;
  const double high_truth = psnr(truth, high->encoded.bytes);
  // Never further from the truth than the model alone (the sample: the residual is dropped when
  // it adds no signal, and the file is the model's, up to the search's choice of bits).
  EXPECT_GE(high_truth, model_truth + min_gain_db - 0.1);
  // Closer to the truth than the input itself: the noise was not coded.
  EXPECT_GT(high_truth, input_truth);
  EXPECT_DOUBLE_EQ(psnr(noisy, high->encoded.bytes), high->chosen.psnr_tonemapped);

  auto within = encode_to_target_ladder(noisy, st, {budget, 0, 1, {6}});
  ASSERT_TRUE(within.ok()) << within.status().message();
  EXPECT_LE(double(within->encoded.bytes.size()), budget);
  EXPECT_GE(psnr(truth, within->encoded.bytes), model_truth + min_gain_db - 0.1);
}

TEST(NoiseLadder, NoisySampleStopsAtTheFloorCloserToTheTruth) {
  auto truth = make_sample("ward");
  ASSERT_TRUE(truth.ok());
  const BrdfTable noisy = testing::with_noise(*truth, 0.03, 5);
  ASSERT_TRUE(estimate_noise(noisy, {.ceiling = false}).noisy());
  // The sample is the model's own kind of BRDF: the model alone is already as close to the truth
  // as a residual gets (61 dB), so no gain is asked, only not losing.
  check_ladder(*truth, noisy, 0, 100000);
}

// A smooth table keeps the ladder of before: no note, the residual searched to the PSNR.
TEST(NoiseLadder, SmoothTableHasNoNote) {
  auto table = make_sample("ward");
  ASSERT_TRUE(table.ok());
  auto r = encode_to_target_ladder(*table, settings(), {0, 55, 1, {6}});
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_TRUE(r->met);
  EXPECT_TRUE(r->note.empty()) << r->note;
}

TEST(NoiseLadder, RealFabricAtThreePercent) {
  const auto dir = testing::noisy_materials_dir("0.03", {"beige-fabric"});
  if (dir.empty()) {
    GTEST_SKIP() << "real materials unavailable: " CBRDF_SHARED_DIR
                    "/data/nbrdf-merl or tools/make-merl.sh missing (or make-merl.sh failed)";
  }
  auto truth = read_merl(dir / "beige-fabric.binary");
  auto noisy = read_merl(dir / "beige-fabric-noisy.binary");
  ASSERT_TRUE(truth.ok() && noisy.ok());
  // The target: +4 dB over the model alone against the truth within 100 KB (measured:
  // +9.1 dB in 35 KB).
  check_ladder(*truth, *noisy, 4.1, 100000);
}

}  // namespace
}  // namespace cbrdf
