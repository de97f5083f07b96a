// SPDX-License-Identifier: MIT
// `--bits auto`: the chosen depth meets its stated loss and one bit fewer does not.
#include <gtest/gtest.h>

#include "cbrdf/encoder.h"
#include "cbrdf/encoder_options.h"
#include "cbrdf/samples.h"
#include "metrics.h"

namespace cbrdf {
namespace {

// The sphere PSNR of `model` written at `bits` with the encoder's container settings (its coding:
// 1.3 where smaller), decoded and compared with the source.
ImageMetrics decoded_psnr(const BrdfTable& source, const Model& model, int bits,
                          ContainerSettings c) {
  c.bits = bits;
  auto bytes = encode_model(model, c);
  EXPECT_TRUE(bytes.ok());
  auto decoded = decode_model(*bytes);
  EXPECT_TRUE(decoded.ok());
  return sphere_psnr(source, decoded->table());
}

bool passes(const ImageMetrics& m, const ImageMetrics& ref, const AutoBitsSettings& a) {
  return m.psnr_tonemapped >= ref.psnr_tonemapped - a.max_tonemapped_loss_db &&
         m.psnr_linear >= ref.psnr_linear - a.max_linear_loss_db;
}

TEST(AutoBits, ChoosesTheFewestBitsWithinTheStatedLoss) {
  int fewer_checked = 0;  // materials whose choice was above 6 bits, so one bit fewer was tried
  for (const char* name : {"ward", "ggx-sharp"}) {
    SCOPED_TRACE(name);
    const BrdfTable table = make_sample(name).value();
    EncoderOptions options;
    ASSERT_EQ(options.bits, "auto");  // the default
    EncoderSettings st = encoder_settings(options).value();
    ASSERT_TRUE(st.auto_bits.enabled);
    auto r = encode_table(table, st);
    ASSERT_TRUE(r.ok()) << r.status().message();
    ASSERT_GE(r->bits, 6);
    ASSERT_LE(r->bits, 16);

    // The file is the model written at the chosen depth, and says so.
    ContainerSettings c = st.container;
    c.bits = r->bits;
    EXPECT_EQ(encode_model(r->model, c).value(), r->bytes);
    EXPECT_EQ(inspect_container(r->bytes).value().bits, r->bits);

    const ImageMetrics ref = sphere_psnr(table, r->model.table());
    EXPECT_TRUE(passes(decoded_psnr(table, r->model, r->bits, st.container), ref, st.auto_bits));
    if (r->bits > 6) {
      EXPECT_FALSE(
          passes(decoded_psnr(table, r->model, r->bits - 1, st.container), ref, st.auto_bits))
          << "bits " << r->bits - 1 << " also meets the loss";
      ++fewer_checked;
    }
  }
  EXPECT_GT(fewer_checked, 0) << "pick samples whose knee is above 6 bits";
}

TEST(AutoBits, ExplicitBitsAreKept) {
  EncoderOptions options;
  options.bits = "9";
  EncoderSettings st = encoder_settings(options).value();
  EXPECT_FALSE(st.auto_bits.enabled);
  EXPECT_EQ(st.container.bits, 9);
  options.bits = "5";
  auto bad = encoder_settings(options);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().message(), "bits must be from 6 to 16, not 5");
}

}  // namespace
}  // namespace cbrdf
