// SPDX-License-Identifier: MIT
// Issue 31, items 5 and 6: a byte budget uses the residual layer where it buys more PSNR than the
// best model alone, and the residual's bound stays relative whatever the table's scale.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "cbrdf/codec.h"
#include "cbrdf/encoder.h"
#include "cbrdf/rate_control.h"
#include "cbrdf/samples.h"
#include "coding_1_2.h"
#include "metrics.h"

namespace cbrdf {
namespace {

// Item 6: at 40,000 bytes the best nickel model alone (6 slices, 1 component, any bits) stayed
// near 50 dB and the budget never reached the residual layer, which on the one-component base
// reaches 60 dB in about 32 KB (`--target-psnr 60`). Now the budget's file holds a residual, fits,
// and beats the model alone by several dB.
TEST(ResidualBudget, ByteBudgetUsesTheResidualLayer) {
  auto table = make_sample("nickel");
  ASSERT_TRUE(table.ok());
  EncoderSettings base = testing::encoder_1_2();
  base.fit.slices = 6;
  const RateTarget target{40000, 0, 1, {6}};
  auto model_only = encode_to_target(*table, base, target);
  ASSERT_TRUE(model_only.ok()) << model_only.status().message();
  auto r = encode_to_target_ladder(*table, base, target);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_TRUE(r->met);
  EXPECT_GT(r->chosen.max_error, 0);
  EXPECT_LE(r->chosen.bytes, 40000);
  EXPECT_EQ(double(r->encoded.bytes.size()), r->chosen.bytes);
  EXPECT_GT(r->chosen.psnr_tonemapped, model_only->chosen.psnr_tonemapped + 3.0)
      << "model alone " << model_only->chosen.psnr_tonemapped << " dB";
  auto decoded = decode_table(r->encoded.bytes);
  ASSERT_TRUE(decoded.ok());
  EXPECT_DOUBLE_EQ(sphere_psnr(*table, *decoded).psnr_tonemapped, r->chosen.psnr_tonemapped);
}

BrdfTable scaled(const BrdfTable& t, double k) {
  BrdfTable out = t;
  for (double& v : out.stored_values()) {
    if (v >= 0) v *= k;
  }
  return out;
}

// The largest |log1p(d / k) - log1p(s / k)| and relative error over the measured bins.
struct Errors {
  double log = 0, relative = 0;
};
Errors errors(const BrdfTable& s, const BrdfTable& d, double knee) {
  Errors e;
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      const double a = s.channel_data(c)[i], b = d.channel_data(c)[i];
      if (!(a >= 0)) continue;
      e.log = std::max(e.log, std::abs(std::log1p(b / knee) - std::log1p(a / knee)));
      if (a > 1e6 * knee) e.relative = std::max(e.relative, std::abs(b - a) / a);
    }
  }
  return e;
}

// Item 5: nickel scaled by 1e-30 with --max-error 1e-3. Before, the knee stayed 1e-4 (stored
// units) far above every value, so the bound was absolute: relative errors of hundreds of percent.
// Now the knee follows the table's scale and every bin well above it is within e^E - 1, as at
// natural scale; a table at natural scale keeps k = 1e-4 (its files are unchanged).
TEST(ResidualBudget, MaxErrorIsRelativeAtAnyScale) {
  auto table = make_sample("nickel");
  ASSERT_TRUE(table.ok());
  for (double k : {1.0, 1e-30, 0x1p-200}) {
    SCOPED_TRACE(k);
    const BrdfTable t = scaled(*table, k);
    EncoderSettings st = testing::encoder_1_2();
    st.fit.slices = 3;
    st.container.bits = 8;
    st.residual.max_error = 1e-3;
    auto r = encode_table(t, st);
    ASSERT_TRUE(r.ok()) << r.status().message();
    const double knee = r->model.residual.knee;
    double peak = 0;
    for (double v : t.stored_values()) peak = std::max(peak, v);
    if (k == 1.0) {
      EXPECT_EQ(knee, 1e-4);
    } else {
      EXPECT_LE(knee, 1e-4 * peak / 4096);  // as far below the peak as at natural scale
    }
    auto d = decode_table(r->bytes);
    ASSERT_TRUE(d.ok());
    const Errors e = errors(t, *d, knee);
    EXPECT_LE(e.log, 1e-3 * (1 + 1e-9));
    EXPECT_LE(e.relative, std::expm1(1e-3) * (1 + 1e-6));
  }
}

}  // namespace
}  // namespace cbrdf
