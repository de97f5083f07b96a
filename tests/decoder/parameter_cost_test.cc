// SPDX-License-Identifier: MIT
// The decoder's work per operation does not grow with the copula family or its parameter:
// components without the product form (Clayton, Gumbel, Joe) at the largest parameters a file may
// hold cost their bins' densities once per evaluator, not at every pair evaluated next to them,
// with the values of the trilinear interpolation between bins; and cbrdf_model_albedo_table
// refuses a table beyond its documented size. (Times are in tests/bench, BM_ParamGrid.)
#define CBRDF_EXPERIMENTAL_API
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "cbrdf/cbrdf_c.h"
#include "cbrdf/coords.h"
#include "cbrdf/file_io.h"
#include "cbrdf/model.h"
#include "copula/registry.h"
#include "density/grid_copula.h"
#include "synthetic_model.h"

namespace cbrdf {
namespace {

// Three slices, each channel a different family at the top of its file range, two components.
Model extreme_generic_model() {
  Model m = testing::make_model({0, 20, 55, 90});
  const CopulaFamily families[3] = {CopulaFamily::kClayton, CopulaFamily::kGumbel,
                                    CopulaFamily::kJoe};
  const double theta[3] = {50.0, 20.0, 20.0};
  for (Slice& s : m.slices) {
    for (int c = 0; c < kChannels; ++c) {
      ChannelSlice& cs = s.channel[std::size_t(c)];
      cs.family = families[c];
      cs.theta = theta[c];
      Component e = cs;
      e.family = families[(c + 1) % 3];
      e.theta = theta[(c + 1) % 3];
      e.scale = 0.5 * cs.scale;
      e.pdf_h = testing::lobe_theta_h(0.03, 1e-5);
      cs.extra.assign(1, e);
    }
  }
  return m;
}

// Pairs at fractional grid positions (h, d, p) inside the grid, away from slice boundaries and
// the phi_d period.
struct Pair {
  double h, d, p;
  Vec3 wi, wo;
};
std::vector<Pair> pairs(int n) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Pair> out;
  while (int(out.size()) < n) {
    Pair q;
    q.h = 0.5 + 80.0 * u(rng);
    q.d = 0.5 + 85.0 * u(rng);
    q.p = 0.5 + 178.0 * u(rng);
    if (std::abs(q.d - 20.0) < 1.5 || std::abs(q.d - 55.0) < 1.5) continue;
    from_half_diff(HalfDiff{theta_h_of(q.h), 0.4, theta_d_of(q.d), phi_d_of(q.p)}, &q.wi, &q.wo);
    if (q.wi.z < 1e-3 || q.wo.z < 1e-3) continue;
    out.push_back(q);
  }
  return out;
}

TEST(ParameterCost, GenericBinsAreEvaluatedOncePerEvaluator) {
  const ModelEvaluator ev(extreme_generic_model());
  const std::vector<Pair> ps = pairs(500);
  internal::GridWorkCounters& counters = internal::grid_work_counters();
  counters = {};
  std::vector<double> first(3 * ps.size());
  for (std::size_t n = 0; n < ps.size(); ++n) ev.eval(ps[n].wi, ps[n].wo, &first[3 * n]);
  const std::uint64_t once = counters.densities;
  // At most 8 bins per pair, 2 components per channel: 48 densities per pair at the most.
  EXPECT_GT(once, 0u);
  EXPECT_LE(once, 48u * ps.size());
  counters = {};
  for (std::size_t n = 0; n < ps.size(); ++n) {
    double rgb[3];
    ev.eval(ps[n].wi, ps[n].wo, rgb);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(rgb[c], first[3 * n + std::size_t(c)]) << n;
  }
  EXPECT_EQ(counters.densities, 0u) << "the same pairs again evaluated " << counters.densities
                                    << " densities (the first time " << once << ")";
}

TEST(ParameterCost, GenericValuesAreTheTrilinearInterpolationOfBinValues) {
  const ModelEvaluator ev(extreme_generic_model());
  int checked = 0;
  for (const Pair& q : pairs(300)) {
    double rgb[3];
    ev.eval(q.wi, q.wo, rgb);
    const int i0 = int(q.h), j0 = int(q.d), k0 = int(q.p);
    const double fh = q.h - i0, fd = q.d - j0, fp = q.p - k0;
    for (int c = 0; c < kChannels; ++c) {
      double ref = 0, top = 0;
      for (int a = 0; a < 2; ++a) {
        for (int b = 0; b < 2; ++b) {
          for (int e = 0; e < 2; ++e) {
            const double v = ev.bin_value(c, i0 + a, j0 + b, k0 + e);
            const double w = (a ? fh : 1 - fh) * (b ? fd : 1 - fd) * (e ? fp : 1 - fp);
            ref += w * v;
            top = std::max(top, v);
          }
        }
      }
      // The pair's position is (h, d, p) up to rounding (about 1e-14 bins).
      EXPECT_NEAR(rgb[c], ref, 1e-12 * ref + 1e-12 * top) << q.h << " " << q.d << " " << q.p;
      ++checked;
    }
  }
  EXPECT_EQ(checked, 900);
}

// The Archimedean grid's inline third derivative gives the family's prepared one's bits: every
// bin of a grid of CDF values, each family from independence to beyond its file range.
TEST(ParameterCost, GridDensityIsTheFamilysPreparedFormulaBitForBit) {
  std::vector<double> u;
  for (int i = 0; i < 40; ++i) u.push_back(std::pow(double(i + 1) / 41.0, 3.0));
  u.push_back(1.0 - 1e-9);
  const struct {
    CopulaFamily family;
    std::vector<double> thetas;
  } cases[] = {{CopulaFamily::kClayton, {0.0, 1e-9, 0.5, 3.0, 50.0, 1e4}},
               {CopulaFamily::kGumbel, {1.0, 1.0 + 1e-9, 2.0, 20.0, 300.0}},
               {CopulaFamily::kJoe, {1.0, 1.5, 20.0, 300.0}}};
  int checked = 0;
  for (const auto& c : cases) {
    const Copula& cop = copula_for(c.family);
    for (double theta : c.thetas) {
      auto grid = internal::make_archimedean_grid(c.family);
      grid->prepare_density(theta, u, u, u);
      const Copula::FastPath path = cop.prepare_fast_path(theta);
      for (std::size_t i = 0; i < u.size(); i += 3) {
        for (std::size_t j = 0; j < u.size(); j += 2) {
          for (std::size_t k = 0; k < u.size(); ++k) {
            const double s = std::exp(cop.log_generator(u[i], theta)) +
                             std::exp(cop.log_generator(u[j], theta)) +
                             std::exp(cop.log_generator(u[k], theta));
            if (!std::isnormal(s)) continue;  // the log-sum path: not the inline one
            const double l = cop.log_abs_generator_derivative(u[i], theta) +
                             cop.log_abs_generator_derivative(u[j], theta) +
                             cop.log_abs_generator_derivative(u[k], theta);
            const double log_c = cop.log_abs_inverse_third_derivative(s, path) + l;
            if (!std::isfinite(log_c)) continue;  // the general path
            const double want = std::isfinite(std::exp(log_c)) ? std::exp(log_c) : 0.0;
            ASSERT_EQ(grid->density(int(i), int(j), int(k)), want)
                << family_name(c.family) << " " << theta << " " << i << " " << j << " " << k;
            ++checked;
          }
        }
      }
    }
  }
  EXPECT_GT(checked, 20000);
}

TEST(ParameterCost, AlbedoTableRefusesATableBeyondItsBound) {
  auto bytes =
      read_file(std::string(CBRDF_TEST_DATA_DIR) + "/golden/v1.0-tiny1-b6.cbrdf", 1u << 20);
  ASSERT_TRUE(bytes.ok()) << bytes.status().message();
  cbrdf_model* m = cbrdf_model_open_memory(bytes->data(), bytes->size());
  ASSERT_NE(m, nullptr) << cbrdf_last_error_message();
  std::vector<double> rgb(3 * 1024, -1.0);
  EXPECT_EQ(cbrdf_model_albedo_table(m, 257, rgb.data(), 1), CBRDF_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(cbrdf_last_error_code(), CBRDF_ERROR_INVALID_ARGUMENT);
  const std::string msg = cbrdf_last_error_message();
  EXPECT_NE(msg.find("n = 257"), std::string::npos) << msg;
  EXPECT_NE(msg.find("1 to 256"), std::string::npos) << msg;
  EXPECT_EQ(rgb[0], -1.0) << "nothing written on failure";
  EXPECT_EQ(cbrdf_model_albedo_table(m, 1024, rgb.data(), 1), CBRDF_ERROR_INVALID_ARGUMENT);
  // Inside the bound: entry 0 is the albedo at its elevation, bit for bit.
  ASSERT_EQ(cbrdf_model_albedo_table(m, 1, rgb.data(), 1), CBRDF_OK);
  const double t = 0.5 * 3.14159265358979323846 / 2;
  const double wo[3] = {std::sin(t), 0.0, std::cos(t)};
  double one[3];
  ASSERT_EQ(cbrdf_model_albedo(m, wo, one, 1), CBRDF_OK);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(rgb[std::size_t(c)], one[c]);
  cbrdf_model_free(m);
}

}  // namespace
}  // namespace cbrdf
