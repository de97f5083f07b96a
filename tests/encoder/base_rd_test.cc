// SPDX-License-Identifier: MIT
// How the BASE writer chooses a marginal table's codes (chunks.h, base_codes): the exact positions
// with the peak on the top code, rate-distortion rounding against plain rounding, and files
// written with it decoding within the stated error.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <random>
#include <vector>

#include "bitstream/chunk_writers.h"
#include "bitstream/mass_quantizer.h"
#include "cbrdf/codec.h"
#include "cbrdf/container_writer.h"
#include "coding_1_2.h"
#include "synthetic_model.h"

namespace cbrdf {
namespace {

// A smooth peaked table with multiplicative noise, as a measured marginal: masses over `n` bins.
std::vector<double> noisy_peak(std::size_t n, double width, double noise, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, noise);
  std::vector<double> m(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double x = double(i) / width;
    m[i] = (std::exp(-x * x) + 0.02 * std::exp(-x / 4)) * std::exp(g(rng));
  }
  return m;
}

TEST(BaseCodes, PeakOnTheTopCodeAndTheSmallestSpan) {
  for (int bits : {6, 9, 12, 16}) {
    const std::vector<double> m = noisy_peak(90, 8.0, 0.01, 3);
    const base_codes::Positions p = base_codes::positions(m, bits);
    const double lmax = std::log(*std::max_element(m.begin(), m.end()));
    const double lmin = std::log(*std::min_element(m.begin(), m.end()));
    // D: a whole number of 1/32 units that holds the log span, at most kSpanSearch above the
    // smallest; no worse than the smallest in the mass-squared-weighted rounding error.
    const double needed = (lmax - lmin) * kRangeGridUnits;
    EXPECT_GE(double(p.span_units), needed - 1e-9);
    EXPECT_LT(double(p.span_units), std::ceil(needed) + base_codes::kSpanSearch + 0.5);
    auto weighted_error = [&](std::uint32_t d) {
      const double step = double(d) / kRangeGridUnits / double(max_code(bits) - 1);
      double e2 = 0;
      for (double v : m) {
        const double pos = double(max_code(bits)) + (std::log(v) - lmax) / step;
        const double e = (std::nearbyint(pos) - pos) * step * (v / std::exp(lmax));
        e2 += e * e;
      }
      return e2;
    };
    EXPECT_LE(weighted_error(p.span_units),
              weighted_error(std::uint32_t(std::ceil(needed))) + 1e-15);
    const std::size_t peak = std::size_t(std::max_element(m.begin(), m.end()) - m.begin());
    EXPECT_EQ(p.position[peak], double(max_code(bits)));  // exact: the peak keeps its value
    EXPECT_EQ(p.weight[peak], 1.0);
    const std::vector<std::uint32_t> q = base_codes::rounded(p);
    EXPECT_EQ(q[peak], max_code(bits));
    for (std::size_t i = 0; i < m.size(); ++i) {
      EXPECT_GE(p.position[i], 1.0);
      EXPECT_LE(p.position[i], double(max_code(bits)));
      // The position is the log mass on the code grid: step D / 32 / (top - 1) per code.
      const double step = double(p.span_units) / kRangeGridUnits / double(max_code(bits) - 1);
      EXPECT_NEAR(p.position[i], double(max_code(bits)) + (std::log(m[i]) - lmax) / step, 1e-6);
    }
  }
  // Zero masses stay exact zeros; an all-zero table has no span.
  std::vector<double> z = {0.0, 1.0, 0.0, 2.0};
  const base_codes::Positions pz = base_codes::positions(z, 8);
  const std::vector<std::uint32_t> qz = base_codes::rounded(pz);
  EXPECT_EQ(qz[0], 0u);
  EXPECT_EQ(qz[2], 0u);
  EXPECT_EQ(qz[3], 255u);
  EXPECT_GE(qz[1], 1u);
  EXPECT_LT(qz[1], 255u);
  EXPECT_EQ(base_codes::positions(std::vector<double>(5, 0.0), 8).span_units, 0u);
}

TEST(BaseCodes, RdRoundingNeverCostsMoreThanPlainRoundingAndStaysNextToEachPosition) {
  int strictly_better = 0, cases = 0;
  for (int bits : {6, 9, 12}) {
    for (unsigned seed = 1; seed <= 6; ++seed) {
      for (std::size_t n : {std::size_t(15), std::size_t(90), std::size_t(180)}) {
        const std::vector<double> m = noisy_peak(n, double(n) / 6, 0.004 * seed, seed);
        const base_codes::Positions p = base_codes::positions(m, bits);
        for (int mode : {0, 1}) {  // the predictors without a reference table
          const base_codes::Predicting how{mode, nullptr, 0, std::int64_t(max_code(bits)),
                                           std::int64_t(max_code(bits))};
          const std::array<internal::SIntContexts, 3> fresh{};
          for (double lambda : {0.0, 0.02, 0.1, 0.5, 2.0}) {
            const std::vector<std::uint32_t> rd = base_codes::rd_rounded(p, how, fresh, lambda);
            const std::vector<std::uint32_t> plain = base_codes::rounded(p);
            const double rd_cost = base_codes::rd_cost(p, rd, how, fresh, lambda);
            const double plain_cost = base_codes::rd_cost(p, plain, how, fresh, lambda);
            EXPECT_LE(rd_cost, plain_cost) << bits << " bits, n " << n << ", lambda " << lambda;
            if (lambda == 0.0) {
              EXPECT_EQ(rd, plain);
            }
            for (std::size_t i = 0; i < n; ++i) {
              EXPECT_LT(std::abs(double(rd[i]) - p.position[i]), 1.0);
              EXPECT_GE(rd[i], 1u);
            }
            ++cases;
            strictly_better += rd_cost < plain_cost - 1e-9;
          }
        }
      }
    }
  }
  // The rounding does something: most cases with lambda > 0 gain (4 of every 5 lambdas are).
  EXPECT_GT(strictly_better, cases / 2) << strictly_better << " of " << cases;
}

TEST(BaseCodes, WrittenFilesDecodeWithinOneCodeStepOfEveryRatio) {
  // Whatever the writer's lambda, a decoded 1.3 table's ratios to its peak are within one code
  // step (plus the grid's rounding of nothing: the peak is exact) of the model's.
  const Model model = testing::make_model({0, 15, 30, 45, 60, 75, 90}, true);
  for (int bits : {6, 10, 14}) {
    ContainerSettings cs = testing::coding_1_2();
    cs.bits = bits;
    cs.format = ContainerSettings::Format::kV13;
    auto bytes = encode_model(model, cs);
    ASSERT_TRUE(bytes.ok()) << bytes.status().message();
    auto decoded = decode_model(*bytes);
    ASSERT_TRUE(decoded.ok()) << decoded.status().message();
    for (std::size_t s = 0; s < model.slices.size(); ++s) {
      for (int c = 0; c < kChannels; ++c) {
        const Component& a = model.slices[s].channel[std::size_t(c)].component(0);
        const Component& b = decoded->slices[s].channel[std::size_t(c)].component(0);
        for (const auto& [x, y] : {std::pair{&a.pdf_h, &b.pdf_h}, std::pair{&a.pdf_d, &b.pdf_d},
                                   std::pair{&a.pdf_p, &b.pdf_p}}) {
          const base_codes::Positions p = base_codes::positions(*x, bits);
          const double step = double(p.span_units) / kRangeGridUnits / double(max_code(bits) - 1);
          const double xmax = *std::max_element(x->begin(), x->end());
          const double ymax = *std::max_element(y->begin(), y->end());
          for (std::size_t i = 0; i < x->size(); ++i) {
            if ((*x)[i] == 0.0) {
              EXPECT_EQ((*y)[i], 0.0);
              continue;
            }
            const double err = std::log((*y)[i] / ymax) - std::log((*x)[i] / xmax);
            EXPECT_LE(std::abs(err), step * (1 + 1e-9)) << "slice " << s << " bits " << bits;
          }
        }
      }
    }
  }
}

TEST(BaseCodes, TablesWhoseSumOverflowsKeepTheirRatiosInBothCodings) {
  // Masses near the double maximum are finite, so a model may hold them, but their sum is not:
  // both quantizers once coded such a table as all zeros (found by fuzz_roundtrip).
  const std::vector<double> m = {6.5e307, 0.0, 1.5e308, 1e290, 1.6e308, 1e300};
  EXPECT_TRUE(std::isinf(m[0] + m[2] + m[4]));
  const std::optional<double> total = log_mass_sum(m);
  ASSERT_TRUE(total.has_value());
  // 6.5e307 + 1.5e308 + 1.6e308 + 1e290 + 1e300 = (3.75 + 1e-8 + 1e-18) e308
  EXPECT_NEAR(*total, std::log(3.75 + 1e-8) + 308.0 * std::log(10.0), 1e-12);
  EXPECT_FALSE(log_mass_sum(std::vector<double>{0.0, -1.0}).has_value());
  EXPECT_EQ(*log_mass_sum(std::vector<double>{2.0, 6.0}), std::log(8.0));  // unchanged when finite

  Model model = testing::make_model({0, 45, 90}, false);
  Component& comp = model.slices[1].channel[2];
  comp.pdf_h.assign(comp.pdf_h.size(), 0.0);  // the six masses alone: a span of 41.9 in log
  std::copy(m.begin(), m.end(), comp.pdf_h.begin());
  for (auto format : {ContainerSettings::Format::kV12, ContainerSettings::Format::kV13}) {
    ContainerSettings cs = testing::coding_1_2();
    cs.bits = 16;  // a step of 6.4e-4 in log mass over the span of 41.9
    cs.format = format;
    auto bytes = encode_model(model, cs);
    ASSERT_TRUE(bytes.ok()) << bytes.status().message();
    auto decoded = decode_model(*bytes);
    ASSERT_TRUE(decoded.ok()) << decoded.status().message();
    const std::vector<double>& d = decoded->slices[1].channel[2].pdf_h;
    ASSERT_GT(d[4], 0.0) << "the table decoded as zeros";
    for (std::size_t i : {0, 2, 3, 5}) {
      EXPECT_NEAR(std::log(d[i] / d[4]), std::log(m[i] / m[4]), 2e-3) << i;
    }
    EXPECT_EQ(d[1], 0.0);
  }
}

}  // namespace
}  // namespace cbrdf
