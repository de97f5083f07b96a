// SPDX-License-Identifier: MIT
// The writer's quantizer of marginal tables (codec/encoder/src/bitstream/mass_quantizer.h) against
// the decoder's reconstruction: codes span the range, and decode within the stated bound.
#include "bitstream/mass_quantizer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace cbrdf {
namespace {

TEST(Quantize, CodesSpanTheRangeAndDecodeWithinTheBound) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> logm(-30.0, 0.0);
  std::vector<double> t(500);
  for (double& v : t) v = std::exp(logm(rng));
  t[17] = 0.0;
  for (int bits = kMinMarginalBits; bits <= kMaxMarginalBits; ++bits) {
    const QuantizedTable q = quantize_masses(t, bits);
    EXPECT_EQ(q.codes[17], 0u);
    EXPECT_EQ(*std::max_element(q.codes.begin(), q.codes.end()), max_code(bits));
    EXPECT_EQ(*std::min_element(q.codes.begin(), q.codes.end()), 0u);
    Expected<std::vector<double>> d = dequantize_masses(q, bits);
    ASSERT_TRUE(d.ok());
    double sum = 0;
    for (double v : t) sum += v;
    double worst = 0;
    for (std::size_t i = 0; i < t.size(); ++i) {
      if (t[i] > 0) worst = std::max(worst, std::abs((*d)[i] / (t[i] / sum) - 1));
    }
    const double bound = relative_error_bound(q, bits);
    EXPECT_LE(worst, bound * (1 + 1e-9));
    EXPECT_GT(worst, 0.3 * bound);  // the bound is tight, not decorative
  }
}

}  // namespace
}  // namespace cbrdf
