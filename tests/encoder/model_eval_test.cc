// SPDX-License-Identifier: MIT
// ModelEvaluator::eval between bins (codec/decoder/src/eval/interp_tables.h): equal to bin_value at
// bin positions, reciprocal, continuous, 0 below the horizon; its difference from the previous eval
// (trilinear between the 8 surrounding bin values, rebuilt here from bin_value and grid_position);
// the float32 path against the float64 one; the batch paths against eval and eval_f32 (bit for bit,
// at 1 and 2 threads); the evaluator's footprint; and decode_model plus an
// evaluator of a small file without a full-table allocation (heap counted by a replaced global
// operator new, this test binary only, as tests/encoder/resource_bounds_test.cc does). Speed is
// measured in tests/bench/codec_bench.cc, never here.
#include <gtest/gtest.h>
#include <malloc.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <new>
#include <random>
#include <string>
#include <vector>

#include "cbrdf/codec.h"
#include "cbrdf/container_writer.h"
#include "cbrdf/fit.h"
#include "cbrdf/merl_io.h"
#include "cbrdf/model.h"
#include "coding_1_2.h"
#include "eval/interp_tables.h"
#include "heap_meter.h"
#include "synthetic_model.h"
#include "test_support.h"

namespace cbrdf {
namespace {

// The previous ModelEvaluator::eval: trilinear in MERL bin position between the 8 surrounding
// bins' values (theta_h, theta_d clamped, phi_d periodic).
void old_eval(const ModelEvaluator& ev, const Vec3& wi, const Vec3& wo, double rgb[3]) {
  rgb[0] = rgb[1] = rgb[2] = 0.0;
  if (wi.z <= 0.0 || wo.z <= 0.0) return;
  const GridPosition g = grid_position(wi, wo);
  const double ph = std::clamp(g.theta_h, 0.0, double(kThetaHBins - 1));
  const double pd = std::clamp(g.theta_d, 0.0, double(kThetaDBins - 1));
  const double pp = std::clamp(g.phi_d, 0.0, double(kPhiDBins));
  const int h0 = std::min(int(ph), kThetaHBins - 1), d0 = std::min(int(pd), kThetaDBins - 1);
  const int p0 = std::min(int(pp), kPhiDBins - 1);
  const double fh = ph - h0, fd = pd - d0, fp = pp - p0;
  for (int a = 0; a < 2; ++a) {
    const double wa = a ? fh : 1 - fh;
    if (wa == 0.0) continue;
    for (int b = 0; b < 2; ++b) {
      const double wb = wa * (b ? fd : 1 - fd);
      if (wb == 0.0) continue;
      for (int e = 0; e < 2; ++e) {
        const double w = wb * (e ? fp : 1 - fp);
        if (w == 0.0) continue;
        for (int c = 0; c < kChannels; ++c)
          rgb[c] += w * ev.bin_value(c, h0 + a, d0 + b, (p0 + e) % kPhiDBins);
      }
    }
  }
}

// Uniform random upper-hemisphere direction pairs (as the bench draws them).
std::vector<Vec3> random_directions(int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Vec3> d(static_cast<std::size_t>(n));
  for (auto& v : d) {
    const double z = u(rng), phi = 2 * M_PI * u(rng), r = std::sqrt(1 - z * z);
    v = {r * std::cos(phi), r * std::sin(phi), z};
  }
  return d;
}

// A model whose every component has the product form: Frank at fitted-like parameters (both
// signs, 0 included) and independence, with 1 to 4 components.
Model frank_model(int max_components) {
  Model m = testing::make_mixture_model(testing::six_slices(), max_components, 7);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (Slice& s : m.slices) {
    for (ChannelSlice& cs : s.channel) {
      for (int r = 0; r < cs.components(); ++r) {
        Component& comp = cs.component(r);
        const double x = u(rng);
        comp.family = x < 0.1 ? CopulaFamily::kIndependence : CopulaFamily::kFrank;
        comp.theta = x < 0.1 ? 0.0 : (x < 0.2 ? 0.0 : (x < 0.35 ? 0.6 : -12.0 * u(rng)));
      }
    }
  }
  return m;
}

// A real material fitted with the default settings (one Frank component per slice and channel);
// an empty model without ../shared.
const Model& fitted_real_material(const std::string& name) {
  static std::map<std::string, Model> fitted;
  auto it = fitted.find(name);
  if (it != fitted.end()) return it->second;
  Model m;
  const auto dir = testing::real_materials_dir();
  if (!dir.empty()) {
    auto t = read_merl(dir / (name + ".binary"));
    if (t.ok()) {
      auto fit = fit_model(*t, FitSettings{});
      if (fit.ok()) m = std::move(fit).value();
    }
  }
  return fitted.emplace(name, std::move(m)).first->second;
}

struct Difference {
  double max_rel = 0, mean_rel = 0;  // relative to the largest of the two values (0 when both 0)
  double max_rel_above = 0;          // the same over values above 1e-3 of the channel's peak
};

// New eval against old over n random pairs.
Difference against_old(const ModelEvaluator& ev, int n) {
  const auto d = random_directions(2 * n, 11);
  std::vector<double> a(std::size_t(3 * n)), b(std::size_t(3 * n));
  double peak[3] = {0, 0, 0};
  for (int i = 0; i < n; ++i) {
    ev.eval(d[std::size_t(2 * i)], d[std::size_t(2 * i + 1)], &a[std::size_t(3 * i)]);
    old_eval(ev, d[std::size_t(2 * i)], d[std::size_t(2 * i + 1)], &b[std::size_t(3 * i)]);
    for (int c = 0; c < 3; ++c) peak[c] = std::max(peak[c], b[std::size_t(3 * i + c)]);
  }
  Difference r;
  std::size_t count = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    const double m = std::max(std::abs(a[k]), std::abs(b[k]));
    if (m == 0) continue;
    const double rel = std::abs(a[k] - b[k]) / m;
    r.max_rel = std::max(r.max_rel, rel);
    r.mean_rel += rel;
    ++count;
    if (b[k] > 1e-3 * peak[k % 3]) r.max_rel_above = std::max(r.max_rel_above, rel);
  }
  r.mean_rel /= double(std::max<std::size_t>(count, 1));
  return r;
}

void expect_bin_positions_and_reciprocity(const ModelEvaluator& ev, double tol) {
  int checked = 0;
  // Not theta_h = 0 or theta_d = 0, where phi_d is not defined by the pair (phi_h = 0 or wi = wo).
  for (int i : {1, 2, 5, 10, 40, 70, 89}) {
    for (int j : {1, 5, 6, 14, 15, 29, 30, 44, 60, 89}) {
      for (int k : {0, 1, 33, 90, 178, 179}) {
        Vec3 wi, wo;
        from_half_diff(HalfDiff{theta_h_of(i), 0.7, theta_d_of(j), phi_d_of(k)}, &wi, &wo);
        if (wi.z <= 1e-9 || wo.z <= 1e-9) continue;
        double a[3], b[3];
        ev.eval(wi, wo, a);
        ev.eval(wo, wi, b);
        for (int c = 0; c < kChannels; ++c) {
          const double v = ev.bin_value(c, i, j, k);
          // The pair's position is the bin's up to rounding (1e-14 bins): a neighbour many decades
          // above the bin (a near-mirror lobe) shows through at that weight.
          double neighbours = 0;
          for (int e = -1; e <= 1; e += 2) {
            neighbours =
                std::max({neighbours, ev.bin_value(c, std::clamp(i + e, 0, kThetaHBins - 1), j, k),
                          ev.bin_value(c, i, std::clamp(j + e, 0, kThetaDBins - 1), k),
                          ev.bin_value(c, i, j, (k + e + kPhiDBins) % kPhiDBins)});
          }
          EXPECT_NEAR(a[c], v, tol * v + 1e-11 * neighbours)
              << c << " " << i << " " << j << " " << k;
          EXPECT_NEAR(a[c], b[c], 1e-9 * a[c]) << c << " " << i << " " << j << " " << k;
        }
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 300);
}

TEST(ModelEval, EqualsBinValueAtBinPositionsAndIsReciprocal) {
  for (int comps : {1, 4}) {
    const ModelEvaluator ev(frank_model(comps));
    expect_bin_positions_and_reciprocity(ev, 1e-6);
  }
  // Every family (Clayton, Gumbel, Joe through their grids) and mixtures of them.
  expect_bin_positions_and_reciprocity(ModelEvaluator(testing::make_model(testing::six_slices())),
                                       1e-6);
  expect_bin_positions_and_reciprocity(
      ModelEvaluator(testing::make_mixture_model(testing::six_slices(), 4)), 1e-6);
}

TEST(ModelEval, ReciprocalOverRandomPairs) {
  const ModelEvaluator ev(frank_model(4));
  const auto d = random_directions(200000, 5);
  double worst = 0;
  for (std::size_t i = 0; i < d.size(); i += 2) {
    double a[3], b[3];
    ev.eval(d[i], d[i + 1], a);
    ev.eval(d[i + 1], d[i], b);
    for (int c = 0; c < 3; ++c) {
      if (a[c] != 0) worst = std::max(worst, std::abs(a[c] - b[c]) / a[c]);
    }
  }
  EXPECT_LT(worst, 1e-10);
}

TEST(ModelEval, ZeroAtAndBelowTheHorizon) {
  const ModelEvaluator ev(frank_model(2));
  double rgb[3];
  ev.eval({0, 0, 1}, {0.6, 0, -0.8}, rgb);
  EXPECT_EQ(rgb[0] + rgb[1] + rgb[2], 0.0);
  ev.eval({1, 0, 0}, {0, 0, 1}, rgb);
  EXPECT_EQ(rgb[0] + rgb[1] + rgb[2], 0.0);
  const float up[3] = {0, 0, 1}, down[3] = {0.6f, 0, -0.8f};
  float f[3];
  ev.eval_f32(up, down, f);
  EXPECT_EQ(f[0] + f[1] + f[2], 0.0f);
  // Normal incidence and exitance (h is the normal, phi_h undefined) is finite.
  ev.eval({0, 0, 1}, {0, 0, 1}, rgb);
  for (double v : rgb) EXPECT_TRUE(std::isfinite(v) && v > 0);
}

TEST(ModelEval, ContinuousAcrossBinsSlicesAndPhiWrap) {
  for (const Model& m : {frank_model(4), testing::make_mixture_model(testing::six_slices(), 3)}) {
    const ModelEvaluator ev(m);
    auto at = [&](double h, double d, double p, int c) {
      Vec3 wi, wo;
      from_half_diff(HalfDiff{theta_h_of(h), 0.3, theta_d_of(d), phi_d_of(p)}, &wi, &wo);
      double v[3];
      ev.eval(wi, wo, v);
      return v[c];
    };
    // A step of 1e-7 bin changes the value by at most 1e-7 of the largest value one bin around
    // (linear between bins); a jump (a slice boundary or the phi_d period not joined) by far more.
    for (int c = 0; c < 3; ++c) {
      auto bound = [&](double h, double d, double p, int axis) {
        double top = 0;
        for (double e : {-1.0, 0.0, 1.0}) {
          top = std::max(top, at(h + (axis == 0 ? e : 0), d + (axis == 1 ? e : 0),
                                 std::fmod(p + (axis == 2 ? e : 0) + 180.0, 180.0), c));
        }
        return 2e-7 * top;
      };
      // Slice boundaries (theta_d bins 6, 15, 30, 50, 70), bin edges on each axis, phi_d wrap.
      for (double d : {6.0, 15.0, 30.0, 50.0, 70.0, 20.0}) {
        const double v = at(20.3, d, 50.5, c), b = bound(20.3, d, 50.5, 1);
        EXPECT_NEAR(at(20.3, d - 1e-7, 50.5, c), v, b) << d;
        EXPECT_NEAR(at(20.3, d + 1e-7, 50.5, c), v, b) << d;
      }
      for (double h : {3.0, 20.0, 41.0}) {
        const double v = at(h, 10.5, 50.5, c), b = bound(h, 10.5, 50.5, 0);
        EXPECT_NEAR(at(h - 1e-7, 10.5, 50.5, c), v, b) << h;
        EXPECT_NEAR(at(h + 1e-7, 10.5, 50.5, c), v, b) << h;
      }
      for (double p : {0.0, 90.0}) {
        const double b = bound(20.3, 10.5, p, 2);
        EXPECT_NEAR(at(20.3, 10.5, std::fmod(p + 180 - 1e-7, 180.0), c), at(20.3, 10.5, p, c), b);
        EXPECT_NEAR(at(20.3, 10.5, p + 1e-7, c), at(20.3, 10.5, p, c), b);
      }
    }
  }
}

// The interpolation changed: the separable part is still trilinear between the 8 surrounding
// bins, the copula's ratio is now evaluated at interpolated per-axis terms. The difference from
// the previous eval is bounded by the copula's variation across one bin.
TEST(ModelEval, DifferenceFromThePreviousEval) {
  struct Case {
    const char* name;
    Model model;
    double max_rel_above;  // bound on values above 1e-3 of the channel's peak
    double mean_rel;       // bound on the mean
  };
  std::vector<Case> cases;
  // Synthetic models are extreme on purpose (Frank alpha to -12, lobes over 12 decades, a CDF
  // jumping by 0.5 across one theta_h bin): there the copula's ratio varies strongly across a bin
  // and the two interpolations differ most. Fitted materials are the realistic case.
  cases.push_back({"synthetic Frank, 1 component", frank_model(1), 0.6, 0.03});
  cases.push_back({"synthetic Frank, up to 4 components", frank_model(4), 0.4, 0.03});
  cases.push_back({"synthetic every family, mixtures",
                   testing::make_mixture_model(testing::six_slices(), 4), 1.0, 0.02});
  for (const char* name : {"blue-metallic-paint", "chrome-steel"}) {
    const Model& m = fitted_real_material(name);
    if (!m.slices.empty()) cases.push_back({name, m, 0.01, 1e-3});
  }
  for (const Case& c : cases) {
    const ModelEvaluator ev(c.model);
    const Difference d = against_old(ev, 100000);
    std::printf(
        "eval vs previous eval, %-36s max rel %.3g, mean rel %.3g, max rel above 1e-3 of "
        "peak %.3g\n",
        c.name, d.max_rel, d.mean_rel, d.max_rel_above);
    EXPECT_LT(d.max_rel_above, c.max_rel_above) << c.name;
    EXPECT_LT(d.mean_rel, c.mean_rel) << c.name;
  }
}

// eval_f32 against eval: relative error bounded where the value is above 1e-6 of the channel's
// peak over the pairs; below, an absolute bound of 1e-6 of the peak.
TEST(ModelEval, Float32PathAgainstFloat64) {
  struct Case {
    Model model;
    double max_rel;  // bound where the value is above 1e-6 of the channel's peak
  };
  // Synthetic models: extreme parameters amplify the float rounding of the copula's ratio
  // (1 - h near e^{-t}) and of the angles near the lobes' sharp peaks.
  std::vector<Case> models = {{frank_model(1), 2e-2},
                              {frank_model(4), 1e-2},
                              {testing::make_mixture_model(testing::six_slices(), 4), 1e-2}};
  for (const char* name : {"blue-metallic-paint", "chrome-steel"}) {
    if (!fitted_real_material(name).slices.empty())
      models.push_back({fitted_real_material(name), 1e-4});
  }
  for (const Case& cs : models) {
    const ModelEvaluator ev(cs.model);
    const int n = 100000;
    const auto d = random_directions(2 * n, 17);
    std::vector<double> a(std::size_t(3 * n)), b(std::size_t(3 * n));
    double peak[3] = {0, 0, 0};
    for (int i = 0; i < n; ++i) {
      const Vec3 &wi = d[std::size_t(2 * i)], &wo = d[std::size_t(2 * i + 1)];
      const float fi[3] = {float(wi.x), float(wi.y), float(wi.z)};
      const float fo[3] = {float(wo.x), float(wo.y), float(wo.z)};
      // The reference at the float directions, so that only the arithmetic differs.
      ev.eval(Vec3{fi[0], fi[1], fi[2]}, Vec3{fo[0], fo[1], fo[2]}, &a[std::size_t(3 * i)]);
      float f[3];
      ev.eval_f32(fi, fo, f);
      for (int c = 0; c < 3; ++c) {
        b[std::size_t(3 * i + c)] = f[c];
        peak[c] = std::max(peak[c], a[std::size_t(3 * i + c)]);
      }
    }
    double max_rel = 0, max_abs_below = 0;
    for (std::size_t k = 0; k < a.size(); ++k) {
      const double p = peak[k % 3];
      if (a[k] > 1e-6 * p) {
        max_rel = std::max(max_rel, std::abs(a[k] - b[k]) / a[k]);
      } else {
        max_abs_below = std::max(max_abs_below, std::abs(a[k] - b[k]) / p);
      }
    }
    std::printf(
        "eval_f32 vs eval: max rel %.3g (values above 1e-6 of peak), max abs %.3g of "
        "peak below\n",
        max_rel, max_abs_below);
    EXPECT_LT(max_rel, cs.max_rel);
    EXPECT_LT(max_abs_below, 1e-6);
  }
}

// Direction pairs for the batch tests: random ones, and the cases eval treats apart (below and at
// the horizon, h along the normal, wi == wo, phi_d at the period's end, NaN).
std::vector<Vec3> batch_directions(int random_pairs) {
  std::vector<Vec3> d = random_directions(2 * random_pairs, 23);
  const double s = std::sqrt(0.5);
  const std::vector<std::pair<Vec3, Vec3>> special = {{{0, 0, 1}, {0, 0, 1}},
                                                      {{s, 0, s}, {-s, 0, s}},
                                                      {{s, 0, s}, {s, 0, s}},
                                                      {{0.6, 0, 0.8}, {0.6, 0, -0.8}},
                                                      {{1, 0, 0}, {0, 0, 1}},
                                                      {{0, s, s}, {0, -s, s}},
                                                      {{0.6, 0.0, 0.8}, {-0.6, 1e-17, 0.8}},
                                                      {{NAN, 0, 1}, {0, 0, 1}}};
  // Among the random pairs (every 37th: inside whole blocks of the batch kernels, which handle
  // such pairs apart from the rest) and again at the end (in the last, partial block).
  for (int k = 0; k < random_pairs; k += 37) {
    const auto& [wi, wo] = special[std::size_t(k / 37) % special.size()];
    d[2 * std::size_t(k)] = wi;
    d[2 * std::size_t(k) + 1] = wo;
  }
  for (const auto& [wi, wo] : special) {
    d.push_back(wi);
    d.push_back(wo);
  }
  return d;
}

TEST(ModelEval, BatchEqualsEvalBitForBit) {
  std::vector<Model> models = {frank_model(1), frank_model(4),
                               testing::make_mixture_model(testing::six_slices(), 4)};
  if (!fitted_real_material("blue-metallic-paint").slices.empty())
    models.push_back(fitted_real_material("blue-metallic-paint"));
  const std::vector<Vec3> d = batch_directions(5000);  // not a multiple of the block or chunk
  const std::size_t n = d.size() / 2;
  std::vector<double> x[6];
  std::vector<float> xf[6];
  std::vector<double> wi3, wo3;
  for (std::size_t k = 0; k < n; ++k) {
    const Vec3 &wi = d[2 * k], &wo = d[2 * k + 1];
    const double v[6] = {wi.x, wi.y, wi.z, wo.x, wo.y, wo.z};
    for (int a = 0; a < 6; ++a) {
      x[a].push_back(v[a]);
      xf[a].push_back(float(v[a]));
    }
    for (int a = 0; a < 3; ++a) {
      wi3.push_back(v[a]);
      wo3.push_back(v[3 + a]);
    }
  }
  for (const Model& m : models) {
    const ModelEvaluator ev(m);
    std::vector<double> want(3 * n);
    std::vector<float> want_f(3 * n);
    for (std::size_t k = 0; k < n; ++k) {
      ev.eval(d[2 * k], d[2 * k + 1], &want[3 * k]);
      const float fi[3] = {xf[0][k], xf[1][k], xf[2][k]}, fo[3] = {xf[3][k], xf[4][k], xf[5][k]};
      ev.eval_f32(fi, fo, &want_f[3 * k]);
    }
    // Every kernel this CPU runs (AVX-512, AVX2, the baseline), then the automatic choice.
    for (internal::BatchTarget target :
         {internal::BatchTarget::kAvx512, internal::BatchTarget::kAvx2,
          internal::BatchTarget::kBaseline, internal::BatchTarget::kAuto}) {
      if (!internal::set_batch_target(target)) continue;
      SCOPED_TRACE(::testing::Message() << "batch target " << int(target));
      for (int threads : {1, 2, 0}) {
        std::vector<double> r(n), g(n), b(n), rgb(3 * n);
        ev.eval_batch(n, x[0].data(), x[1].data(), x[2].data(), x[3].data(), x[4].data(),
                      x[5].data(), r.data(), g.data(), b.data(), threads);
        ev.eval_batch(n, wi3.data(), wo3.data(), rgb.data(), threads);
        std::vector<float> rf(n), gf(n), bf(n);
        ev.eval_batch_f32(n, xf[0].data(), xf[1].data(), xf[2].data(), xf[3].data(), xf[4].data(),
                          xf[5].data(), rf.data(), gf.data(), bf.data(), threads);
        int differ = 0, differ_f = 0;
        for (std::size_t k = 0; k < n; ++k) {
          const double soa[3] = {r[k], g[k], b[k]};
          const float soa_f[3] = {rf[k], gf[k], bf[k]};
          differ += std::memcmp(soa, &want[3 * k], sizeof soa) != 0;
          differ += std::memcmp(&rgb[3 * k], &want[3 * k], sizeof soa) != 0;
          differ_f += std::memcmp(soa_f, &want_f[3 * k], sizeof soa_f) != 0;
        }
        EXPECT_EQ(differ, 0) << "threads " << threads;
        EXPECT_EQ(differ_f, 0) << "threads " << threads;
      }
    }
    ev.eval_batch(0, nullptr, nullptr, nullptr, nullptr, nullptr, nullptr, nullptr, nullptr,
                  nullptr);  // n == 0 reads nothing
  }
}

TEST(ModelEval, FootprintIsSmallAndGrowsWithComponents) {
  const ModelEvaluator one(frank_model(1));
  const ModelEvaluator four(frank_model(4));
  std::printf("footprint_bytes: 1 component %zu, up to 4 components %zu\n", one.footprint_bytes(),
              four.footprint_bytes());
  EXPECT_GT(one.footprint_bytes(), 50000u);
  EXPECT_LT(one.footprint_bytes(), 1u << 20);  // the measured table is 35 MB
  EXPECT_GT(four.footprint_bytes(), one.footprint_bytes());
  EXPECT_LT(four.footprint_bytes(), 4u << 20);
}

// decode_model of a small file and an evaluator of it allocate nothing of a full table's size
// (3 x 1,458,000 doubles, 35 MB): the peak heap is that of the model and the evaluator.
TEST(ModelEval, DecodeAndEvaluateWithoutAFullTable) {
  auto bytes = encode_model(frank_model(1), testing::coding_1_2());
  ASSERT_TRUE(bytes.ok()) << bytes.status().message();
  std::printf("file: %zu bytes\n", bytes->size());
  testing::heap::Meter meter;
  meter.start();
  std::size_t footprint = 0;
  {
    Expected<Model> model = decode_model(*bytes);
    ASSERT_TRUE(model.ok()) << model.status().message();
    const ModelEvaluator ev(std::move(model).value());
    double rgb[3];
    ev.eval({0.3, 0.1, std::sqrt(0.9)}, {-0.2, 0.25, std::sqrt(1 - 0.1025)}, rgb);
    EXPECT_GT(rgb[0], 0.0);
    footprint = ev.footprint_bytes();
  }
  const std::size_t peak = meter.peak_bytes(), largest = meter.largest_bytes();
  std::printf(
      "decode_model + ModelEvaluator + eval: peak heap %zu bytes, largest allocation %zu "
      "bytes, evaluator footprint %zu bytes\n",
      peak, largest, footprint);
  constexpr std::size_t kTableBytes = std::size_t{3} * kBinsPerChannel * sizeof(double);
  EXPECT_LT(largest, kTableBytes / 3 / 8) << "no channel-sized allocation";
  EXPECT_LT(peak, kTableBytes / 8);
}

}  // namespace
}  // namespace cbrdf
