// SPDX-License-Identifier: MIT
// BrdfSampler: chi-square goodness of fit of sample() against pdf() (as pbrt and Mitsuba test their
// BSDFs), normalization, and the variance gain over cosine-weighted sampling.
#include "cbrdf/sampling.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "cbrdf/analytic.h"
#include "cbrdf/fit.h"
#include "cbrdf/samples.h"
#include "sampling_math.h"
#include "synthetic_model.h"

namespace cbrdf {
namespace {

constexpr double kPi = std::numbers::pi;

Vec3 direction(double theta_deg, double phi) {
  const double t = theta_deg * kPi / 180;
  return {std::sin(t) * std::cos(phi), std::sin(t) * std::sin(phi), std::cos(t)};
}

BrdfFn analytic_fn(const AnalyticBrdf& brdf) {
  return [brdf](const Vec3& wi, const Vec3& wo, double rgb[3]) { brdf.eval(wi, wo, rgb); };
}

// ---- Chi-square test ----

// Regularized upper incomplete gamma Q(a, x) (Numerical Recipes: series below a + 1, continued
// fraction above).
double gamma_q(double a, double x) {
  if (x <= 0) return 1.0;
  const double gln = std::lgamma(a);
  if (x < a + 1) {
    double ap = a, sum = 1.0 / a, del = sum;
    for (int n = 0; n < 10000; ++n) {
      ap += 1;
      del *= x / ap;
      sum += del;
      if (std::abs(del) < std::abs(sum) * 1e-15) break;
    }
    return 1.0 - sum * std::exp(-x + a * std::log(x) - gln);
  }
  double b = x + 1 - a, c = 1e300, d = 1 / b, h = d;
  for (int i = 1; i < 10000; ++i) {
    const double an = -i * (i - a);
    b += 2;
    d = an * d + b;
    if (std::abs(d) < 1e-300) d = 1e-300;
    c = b + an / c;
    if (std::abs(c) < 1e-300) c = 1e-300;
    d = 1 / d;
    const double del = d * c;
    h *= del;
    if (std::abs(del - 1) < 1e-15) break;
  }
  return std::exp(-x + a * std::log(x) - gln) * h;
}

// wi bins over the upper hemisphere (uniform in theta and phi) plus one bin for rejected draws.
constexpr int kThetaBins = 24, kPhiBins = 48;
constexpr int kRejectedBin = kThetaBins * kPhiBins;

int wi_bin(const Vec3& wi) {
  const double theta = std::acos(std::clamp(wi.z, -1.0, 1.0));
  double phi = std::atan2(wi.y, wi.x);
  if (phi < 0) phi += 2 * kPi;
  const int a = std::clamp(int(theta / (kPi / 2) * kThetaBins), 0, kThetaBins - 1);
  const int b = std::clamp(int(phi / (2 * kPi) * kPhiBins), 0, kPhiBins - 1);
  return a * kPhiBins + b;
}

// The probability of each wi bin: the integral of pdf() over it, taken over half vectors
// (dwi = 4 (wo.h) dh, exact) on a sub-grid nested in the sampler's theta_h and phi_h cells, where
// the tabulated density is constant; each sub-cell's solid angle is exact. The rejected bin gets
// 1 minus the total.
std::vector<double> expected_probabilities(const BrdfSampler& s, const Vec3& wo, double* total) {
  const SamplerSettings& st = s.settings();
  const int nt = st.theta_h_cells * 24, np = st.phi_h_cells * 24;
  const double r = std::hypot(wo.x, wo.y);
  const double xx = r > 1e-12 ? wo.x / r : 1.0, xy = r > 1e-12 ? wo.y / r : 0.0;
  std::vector<double> p(kRejectedBin + 1, 0.0);
  double sum = 0.0;
  const double dphi = 2 * kPi / np;
  for (int a = 0; a < nt; ++a) {
    const double t0 = double(a) / nt, t1 = double(a + 1) / nt;
    const double c0 = std::cos(t0 * t0 * kPi / 2),
                 c1 = a + 1 == nt ? 0.0 : std::cos(t1 * t1 * kPi / 2);
    const double tm = (t0 + t1) / 2, theta = tm * tm * kPi / 2;
    const double ct = std::cos(theta), st_ = std::sin(theta);
    for (int b = 0; b < np; ++b) {
      const double phi = (b + 0.5) * dphi;
      const double hx = st_ * std::cos(phi), hy = st_ * std::sin(phi);
      const Vec3 h{xx * hx - xy * hy, xy * hx + xx * hy, ct};
      const double d = dot(wo, h);
      if (d <= 0) continue;
      const Vec3 wi{2 * d * h.x - wo.x, 2 * d * h.y - wo.y, 2 * d * h.z - wo.z};
      if (wi.z <= 0) continue;
      const double mass = s.sample_pdf(wi, wo) * 4 * d * (c0 - c1) * dphi;
      p[std::size_t(wi_bin(wi))] += mass;
      sum += mass;
    }
  }
  p[kRejectedBin] = std::max(0.0, 1.0 - sum);
  *total = sum;
  return p;
}

struct ChiSquare {
  double p_value = 0;
  int dof = 0;
  std::string detail;
};

// batch: the draws through BrdfSampler::sample_batch (structure of arrays, 2 threads), which must
// also equal sample() bit for bit on the first draws.
ChiSquare chi_square(const BrdfSampler& s, const Vec3& wo, int n, std::uint64_t seed,
                     bool batch = false) {
  double total = 0;
  const std::vector<double> expected_p = expected_probabilities(s, wo, &total);
  std::vector<double> observed(expected_p.size(), 0.0);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  if (!batch) {
    for (int i = 0; i < n; ++i) {
      const BrdfSample smp = s.sample(wo, u(rng), u(rng));
      observed[std::size_t(smp.valid ? wi_bin(smp.wi) : kRejectedBin)] += 1;
    }
  } else {
    const std::size_t m = std::size_t(n);
    std::vector<double> ox(m, wo.x), oy(m, wo.y), oz(m, wo.z), u1(m), u2(m);
    for (std::size_t i = 0; i < m; ++i) {
      u1[i] = u(rng);
      u2[i] = u(rng);
    }
    std::vector<double> x(m), y(m), z(m), pdf(m), wr(m), wg(m), wb(m);
    s.sample_batch(m, ox.data(), oy.data(), oz.data(), u1.data(), u2.data(), x.data(), y.data(),
                   z.data(), pdf.data(), wr.data(), wg.data(), wb.data(), 2);
    int differ = 0;
    for (std::size_t i = 0; i < m; ++i) {
      const bool valid = pdf[i] > 0;
      if (i < 5000) {
        const BrdfSample smp = s.sample(wo, u1[i], u2[i]);
        const Vec3 wi{x[i], y[i], z[i]};
        differ += smp.valid != valid;
        if (smp.valid && valid) {
          differ += std::memcmp(&smp.wi, &wi, sizeof wi) != 0 || smp.pdf != pdf[i];
        } else {
          differ +=
              !(x[i] == 0 && y[i] == 0 && z[i] == 0 && wr[i] == 0 && wg[i] == 0 && wb[i] == 0);
        }
      }
      observed[std::size_t(valid ? wi_bin(Vec3{x[i], y[i], z[i]}) : kRejectedBin)] += 1;
    }
    EXPECT_EQ(differ, 0) << "sample_batch differs from sample()";
  }
  ChiSquare r;
  // Pool bins expecting fewer than 5 draws (the usual validity condition of the test).
  double chi2 = 0, pooled_e = 0, pooled_o = 0;
  int cells = 0;
  for (std::size_t i = 0; i < expected_p.size(); ++i) {
    const double e = expected_p[i] * n;
    if (e == 0 && observed[i] > 0) {
      r.detail = "bin " + std::to_string(i) + " has draws but zero probability";
      return r;
    }
    if (e < 5) {
      pooled_e += e;
      pooled_o += observed[i];
      continue;
    }
    chi2 += (observed[i] - e) * (observed[i] - e) / e;
    ++cells;
  }
  if (pooled_e > 0) {
    chi2 += (pooled_o - pooled_e) * (pooled_o - pooled_e) / pooled_e;
    ++cells;
  }
  r.dof = cells - 1;
  r.p_value = gamma_q(r.dof / 2.0, chi2 / 2.0);
  r.detail = "chi2 " + std::to_string(chi2) + " dof " + std::to_string(r.dof) + ", pdf integral " +
             std::to_string(total) + ", rejected " + std::to_string(observed[kRejectedBin] / n);
  return r;
}

struct Material {
  std::string name;
  BrdfFn fn;
};

const Model& fitted_near_mirror() {
  static const Model m = [] {
    auto table = make_sample("near-mirror");
    EXPECT_TRUE(table.ok());
    auto fitted = fit_model(*table, FitSettings{});
    EXPECT_TRUE(fitted.ok()) << fitted.status().message();
    return *fitted;
  }();
  return m;
}

TEST(Sampling, ChiSquareAgainstPdfForSeveralMaterialsAndDirections) {
  const Model synthetic = testing::make_model(testing::six_slices(), /*peaked=*/true);
  const ModelEvaluator synthetic_eval(synthetic);
  const ModelEvaluator fitted_eval(fitted_near_mirror());
  std::vector<Material> materials = {
      {"lambertian", analytic_fn(*sample_brdf("lambertian"))},
      {"ggx-sharp", analytic_fn(*sample_brdf("ggx-sharp"))},
      {"near-mirror (analytic)", analytic_fn(*sample_brdf("near-mirror"))},
      {"near-mirror (fitted copula model)", model_brdf_fn(fitted_eval)},
      {"synthetic copula model (all families, peaked G)", model_brdf_fn(synthetic_eval)},
  };
  const std::vector<Vec3> wos = {direction(0, 0), direction(35, 0.7), direction(70, 2.5),
                                 direction(86, -1.2)};
  const int tests = int(materials.size() * wos.size());
  const double alpha = 0.01 / tests;  // Sidak-style correction over all cases
  std::uint64_t seed = 1;
  for (const Material& m : materials) {
    const BrdfSampler sampler(m.fn);
    for (const Vec3& wo : wos) {
      const ChiSquare r = chi_square(sampler, wo, 200000, seed++);
      EXPECT_GT(r.dof, 10) << m.name;
      EXPECT_GT(r.p_value, alpha) << m.name << " wo.z " << wo.z << ": " << r.detail;
    }
  }
}

// The same chi-square test on the batch path, for a model sampler (weights through the
// evaluator's batch) and a generic one (weights through f); and the batch's weights against
// eval per draw, bit for bit.
TEST(Sampling, ChiSquareOnTheBatchPath) {
  const ModelEvaluator fitted_eval(fitted_near_mirror());
  const BrdfSampler model_sampler = make_model_sampler(fitted_eval);
  const BrdfSampler analytic_sampler(analytic_fn(*sample_brdf("ggx-sharp")));
  const std::vector<Vec3> wos = {direction(0, 0), direction(35, 0.7), direction(70, 2.5),
                                 direction(86, -1.2)};
  const double alpha = 0.01 / double(2 * wos.size());
  std::uint64_t seed = 101;
  for (const BrdfSampler* s : {&model_sampler, &analytic_sampler}) {
    for (const Vec3& wo : wos) {
      const ChiSquare r = chi_square(*s, wo, 200000, seed++, /*batch=*/true);
      EXPECT_GT(r.dof, 10);
      EXPECT_GT(r.p_value, alpha) << "wo.z " << wo.z << ": " << r.detail;
    }
  }
  // Interleaved form and weights: f(wi, wo) cos / pdf with f = eval, bit for bit; rejections 0.
  const int n = 3001;
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> wo(3 * n), uu(2 * n), wi(3 * n), pdf(n), w(3 * n);
  for (int k = 0; k < n; ++k) {
    const Vec3 o = k % 50 == 0 ? Vec3{0.6, 0.0, -0.8} : direction(85 * u(rng), 6 * u(rng));
    wo[3 * k] = o.x;
    wo[3 * k + 1] = o.y;
    wo[3 * k + 2] = o.z;
    uu[2 * k] = u(rng);
    uu[2 * k + 1] = u(rng);
  }
  model_sampler.sample_batch(std::size_t(n), wo.data(), uu.data(), wi.data(), pdf.data(), w.data());
  int differ = 0, rejected = 0;
  for (int k = 0; k < n; ++k) {
    const Vec3 o{wo[3 * k], wo[3 * k + 1], wo[3 * k + 2]};
    const BrdfSample smp = model_sampler.sample(o, uu[2 * k], uu[2 * k + 1]);
    if (!smp.valid) {
      ++rejected;
      differ += pdf[k] != 0 || w[3 * k] != 0 || wi[3 * k + 2] != 0;
      continue;
    }
    double f[3];
    fitted_eval.eval(smp.wi, o, f);
    differ += pdf[k] != smp.pdf || wi[3 * k] != smp.wi.x || wi[3 * k + 2] != smp.wi.z;
    for (int c = 0; c < 3; ++c) differ += w[3 * k + c] != f[c] * smp.wi.z / smp.pdf;
  }
  EXPECT_EQ(differ, 0);
  EXPECT_GE(rejected, n / 50);  // the wo below the horizon at least
}

// sample_batch equals sample() bit for bit, and each draw's pdf equals pdf() with weights
// f cos / pdf, for other table shapes (cell counts that are not multiples of a vector or a cache
// line, all-table and all-cosine mixtures), wo at normal incidence and below the horizon, and u
// at and outside the ends of [0, 1) and NaN; the generic path (weights through f).
TEST(Sampling, BatchEqualsSampleForOtherSettings) {
  const AnalyticBrdf brdf = *sample_brdf("ggx-sharp");
  const std::vector<SamplerSettings> settings = {
      {.theta_o_bins = 8, .theta_h_cells = 13, .phi_h_cells = 7, .cosine_fraction = 0.0},
      {.theta_o_bins = 5, .theta_h_cells = 40, .phi_h_cells = 129, .cosine_fraction = 1.0},
      {.theta_o_bins = 3, .theta_h_cells = 17, .phi_h_cells = 33, .cosine_fraction = 0.3}};
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double ends[] = {0.0, std::nextafter(1.0, 0.0), 1.0, -0.5, 1.5, nan};
  for (const SamplerSettings& st : settings) {
    const BrdfSampler s(analytic_fn(brdf), st);
    const int n = 2000;
    std::mt19937_64 rng(st.phi_h_cells);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<double> ox(n), oy(n), oz(n), u1(n), u2(n);
    for (int k = 0; k < n; ++k) {
      const Vec3 o = k % 97 == 0   ? Vec3{0, 0, 1}
                     : k % 89 == 0 ? direction(95, 1.0)
                                   : direction(89.9 * u(rng), 7 * u(rng));
      ox[k] = o.x;
      oy[k] = o.y;
      oz[k] = o.z;
      u1[k] = k % 31 == 0 ? ends[(k / 31) % 6] : u(rng);
      u2[k] = k % 37 == 0 ? ends[(k / 37) % 6] : u(rng);
    }
    std::vector<double> x(n), y(n), z(n), pdf(n), w[3];
    for (auto& c : w) c.resize(n);
    s.sample_batch(n, ox.data(), oy.data(), oz.data(), u1.data(), u2.data(), x.data(), y.data(),
                   z.data(), pdf.data(), w[0].data(), w[1].data(), w[2].data(), 1);
    int differ = 0, valid = 0, table_draws = 0;
    for (int k = 0; k < n; ++k) {
      const Vec3 o{ox[k], oy[k], oz[k]};
      const BrdfSample smp = s.sample(o, u1[k], u2[k]);
      if (!smp.valid) {
        differ += pdf[k] != 0 || x[k] != 0 || y[k] != 0 || z[k] != 0 || w[0][k] != 0;
        continue;
      }
      ++valid;
      // The table shares the density unless the mixture is all cosine.
      table_draws += std::abs(smp.wi.z * st.cosine_fraction / kPi - smp.pdf) > 1e-12;
      double f[3];
      brdf.eval(smp.wi, o, f);
      differ += x[k] != smp.wi.x || y[k] != smp.wi.y || z[k] != smp.wi.z || pdf[k] != smp.pdf;
      differ += !(smp.wi.z > 0) || s.sample_pdf(smp.wi, o) != smp.pdf;
      for (int c = 0; c < 3; ++c) differ += w[c][k] != f[c] * smp.wi.z / smp.pdf;
    }
    EXPECT_EQ(differ, 0) << "phi_h_cells " << st.phi_h_cells;
    EXPECT_GT(valid, n / 2) << "phi_h_cells " << st.phi_h_cells;
    if (st.cosine_fraction < 1) {
      EXPECT_GT(table_draws, n / 4) << "phi_h_cells " << st.phi_h_cells;
    }
  }
}

// The sampler's own trigonometry (sampling_math.h, written to vectorize) agrees with libm to a
// few ulp over the ranges the sampler uses, and at their ends.
TEST(SamplingMath, AgreesWithLibm) {
  using internal::acos01, internal::atan2_0_2pi, internal::sincos_0_2pi, internal::SinCos;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double acos_err = 0, sincos_err = 0, atan2_err = 0;
  for (int i = 0; i < 300000; ++i) {
    const double x = i % 3 == 0 ? u(rng) : i % 3 == 1 ? 1 - 1e-7 * u(rng) : 1e-4 * u(rng);
    acos_err = std::max(acos_err, std::abs(acos01(x) - std::acos(x)) / std::acos(x));
    const double phi = 2 * kPi * u(rng);
    const SinCos sc = sincos_0_2pi(phi);
    sincos_err =
        std::max({sincos_err, std::abs(sc.s - std::sin(phi)), std::abs(sc.c - std::cos(phi))});
    const double ay = (2 * u(rng) - 1) * (i % 5 == 0 ? 1e-9 : 1.0), ax = 2 * u(rng) - 1;
    double want = std::atan2(ay, ax);
    if (want < 0) want += 2 * kPi;
    if (want > 0) atan2_err = std::max(atan2_err, std::abs(atan2_0_2pi(ay, ax) - want) / want);
  }
  EXPECT_LT(acos_err, 1e-15);
  EXPECT_LT(sincos_err, 1e-15);
  EXPECT_LT(atan2_err, 1e-15);
  EXPECT_EQ(acos01(1.0), 0.0);
  EXPECT_EQ(acos01(0.0), std::acos(0.0));
  EXPECT_EQ(acos01(2.0), 0.0);  // clamped into [0, 1], NaN to 0
  EXPECT_EQ(acos01(std::numeric_limits<double>::quiet_NaN()), std::acos(0.0));
  EXPECT_EQ(sincos_0_2pi(0.0).s, 0.0);
  EXPECT_EQ(sincos_0_2pi(0.0).c, 1.0);
  EXPECT_NEAR(sincos_0_2pi(kPi / 2).c, 0.0, 1e-16);
  EXPECT_EQ(atan2_0_2pi(0.0, 0.0), 0.0);
  EXPECT_EQ(atan2_0_2pi(0.0, -1.0), kPi);
  EXPECT_EQ(atan2_0_2pi(-0.0, -1.0), kPi);
  EXPECT_EQ(atan2_0_2pi(-1.0, 0.0), 1.5 * kPi);
  EXPECT_LE(atan2_0_2pi(-1e-300, 1.0), 2 * kPi);
}

// The test above must be able to fail: a density off by a Jacobian factor is rejected.
TEST(Sampling, ChiSquareRejectsAWrongDensity) {
  const AnalyticBrdf brdf = *sample_brdf("ggx-sharp");
  const BrdfSampler right(analytic_fn(brdf));
  // Draws from a different material (rougher) but the density of the sharp one.
  const BrdfSampler drawn(analytic_fn(*sample_brdf("ggx-rough")));
  const Vec3 wo = direction(35, 0.3);
  double total = 0;
  const std::vector<double> expected_p = expected_probabilities(right, wo, &total);
  std::vector<double> observed(expected_p.size(), 0.0);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const BrdfSample smp = drawn.sample(wo, u(rng), u(rng));
    observed[std::size_t(smp.valid ? wi_bin(smp.wi) : kRejectedBin)] += 1;
  }
  double chi2 = 0;
  int cells = 0;
  for (std::size_t i = 0; i < expected_p.size(); ++i) {
    const double e = expected_p[i] * n;
    if (e < 5) continue;
    chi2 += (observed[i] - e) * (observed[i] - e) / e;
    ++cells;
  }
  EXPECT_LT(gamma_q((cells - 1) / 2.0, chi2 / 2.0), 1e-6);
}

TEST(Sampling, GammaQMatchesKnownValues) {
  // Chi-square survival function: Q(k/2, x/2). Values from the chi-square tables.
  EXPECT_NEAR(gamma_q(1.0 / 2, 3.841 / 2), 0.05, 1e-4);
  EXPECT_NEAR(gamma_q(10.0 / 2, 23.209 / 2), 0.01, 1e-4);
  EXPECT_NEAR(gamma_q(100.0 / 2, 124.342 / 2), 0.05, 1e-4);
}

// Normalization seen from wi directly: a plain midpoint rule over the wi hemisphere (independent
// of the half-vector change of variables) agrees with the half-vector integral, and both equal the
// share of draws that are not rejected.
TEST(Sampling, PdfIntegratesToAcceptedShare) {
  const BrdfSampler s(analytic_fn(*sample_brdf("ggx-rough")));
  for (double theta_o : {10.0, 60.0, 85.0}) {
    const Vec3 wo = direction(theta_o, 0.4);
    double h_total = 0;
    (void)expected_probabilities(s, wo, &h_total);
    const int nt = 600, np = 1200;
    double wi_total = 0;
    for (int a = 0; a < nt; ++a) {
      const double c0 = 1.0 - double(a) / nt, c1 = 1.0 - double(a + 1) / nt;
      const double ct = (c0 + c1) / 2, st = std::sqrt(1 - ct * ct);
      for (int b = 0; b < np; ++b) {
        const double phi = (b + 0.5) * 2 * kPi / np;
        wi_total += s.sample_pdf({st * std::cos(phi), st * std::sin(phi), ct}, wo) * (c0 - c1) * 2 *
                    kPi / np;
      }
    }
    EXPECT_NEAR(wi_total, h_total, 2e-3) << theta_o;
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    int accepted = 0;
    const int n = 200000;
    for (int i = 0; i < n; ++i) {
      const BrdfSample smp = s.sample(wo, u(rng), u(rng));
      if (smp.valid) {
        ++accepted;
        EXPECT_GT(smp.wi.z, 0);
        EXPECT_DOUBLE_EQ(smp.pdf, s.sample_pdf(smp.wi, wo));
      } else {
        EXPECT_EQ(smp.pdf, 0.0);
      }
    }
    const double share = double(accepted) / n;
    EXPECT_NEAR(share, h_total, 5 * std::sqrt(share * (1 - share) / n) + 1e-4) << theta_o;
    EXPECT_LE(h_total, 1.0 + 1e-9);
    if (theta_o < 20) {
      EXPECT_GT(h_total, 0.999);  // nothing reflects below the horizon near normal incidence
    }
  }
}

TEST(Sampling, BelowHorizonAndBlackMaterials) {
  const BrdfSampler s(analytic_fn(*sample_brdf("plastic")));
  EXPECT_EQ(s.sample_pdf(direction(95, 1), direction(30, 0)), 0.0);
  EXPECT_EQ(s.sample_pdf(direction(30, 1), direction(95, 0)), 0.0);
  EXPECT_FALSE(s.sample(direction(95, 0), 0.5, 0.5).valid);
  // A black BRDF falls back to cosine sampling entirely.
  const BrdfSampler black(
      [](const Vec3&, const Vec3&, double rgb[3]) { rgb[0] = rgb[1] = rgb[2] = 0; });
  const Vec3 wo = direction(40, 0), wi = direction(20, 2);
  EXPECT_NEAR(black.sample_pdf(wi, wo), wi.z / kPi, 1e-15);
  const BrdfSample smp = black.sample(wo, 0.3, 0.6);
  ASSERT_TRUE(smp.valid);
  const Vec3 cos_wi = sample_cosine_hemisphere(0.3, 0.6);
  EXPECT_NEAR(smp.wi.x, cos_wi.x, 1e-15);
  EXPECT_NEAR(smp.wi.z, cos_wi.z, 1e-15);
  // A NaN draw is rejected, on a table with rows and on an empty one (nothing to search), and
  // on the batch path as on the scalar one.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const BrdfSampler* sm : {&s, &black}) {
    for (const auto& [u1, u2] : {std::pair{nan, 0.5}, {0.99, nan}, {nan, nan}}) {
      const BrdfSample r = sm->sample(wo, u1, u2);
      EXPECT_FALSE(r.valid);
      EXPECT_EQ(r.pdf, 0.0);
    }
    const double wo3[3] = {wo.x, wo.y, wo.z}, u[2] = {nan, 0.5};
    double wi3[3] = {1, 1, 1}, pdf = 1, weight[3] = {1, 1, 1};
    sm->sample_batch(1, wo3, u, wi3, &pdf, weight);
    EXPECT_EQ(pdf, 0.0);
    EXPECT_EQ(weight[0], 0.0);
  }
}

// Equal sample counts, one glossy material (the fitted copula model of the polished-gold sample)
// lit by an environment with a sky gradient and a small bright sun: the per-sample variance of the
// estimator f cos L / pdf under cosine-weighted sampling and under the model's importance sampling.
TEST(Sampling, ImportanceSamplingBeatsCosineSamplingForAGlossyMaterial) {
  auto table = make_sample("ggx-sharp");
  ASSERT_TRUE(table.ok());
  auto model = fit_model(*table, FitSettings{});
  ASSERT_TRUE(model.ok());
  const ModelEvaluator eval(*model);
  const BrdfSampler sampler = make_model_sampler(eval);
  const Vec3 sun = direction(40, kPi);  // near the mirror direction of wo
  auto env = [&](const Vec3& w) {
    const double sky = 0.3 + 0.7 * std::max(0.0, w.z);
    return sky + 40.0 * std::exp((dot(w, sun) - 1) / 0.002);
  };
  const Vec3 wo = direction(45, 0);
  auto estimate = [&](bool importance, std::uint64_t seed, double* mean) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const int n = 200000;
    double s1 = 0, s2 = 0;
    for (int i = 0; i < n; ++i) {
      double x = 0;
      Vec3 wi;
      double pdf = 0;
      if (importance) {
        const BrdfSample smp = sampler.sample(wo, u(rng), u(rng));
        wi = smp.wi;
        pdf = smp.valid ? smp.pdf : 0;
      } else {
        const double u1 = u(rng), u2 = u(rng);
        wi = sample_cosine_hemisphere(u1, u2);
        pdf = wi.z / kPi;
      }
      if (pdf > 0) {
        double f[3];
        eval.eval(wi, wo, f);
        x = (f[0] + f[1] + f[2]) / 3 * wi.z * env(wi) / pdf;
      }
      s1 += x;
      s2 += x * x;
    }
    *mean = s1 / n;
    return s2 / n - *mean * *mean;
  };
  double mean_cos = 0, mean_is = 0;
  const double var_cos = estimate(false, 11, &mean_cos);
  const double var_is = estimate(true, 12, &mean_is);
  // Both are unbiased estimates of the same integral.
  const double se = std::sqrt(var_cos / 200000) + std::sqrt(var_is / 200000);
  EXPECT_NEAR(mean_cos, mean_is, 5 * se);
  const double ratio = var_cos / var_is;
  std::printf(
      "[ measured ] glossy model under a sun+sky environment: variance cosine %.4g, "
      "importance %.4g, ratio %.1f (radiance %.4f)\n",
      var_cos, var_is, ratio, mean_is);
  EXPECT_GT(ratio, 10.0);
}

// The evaluator owns its model and a sampler made from a shared evaluator keeps it alive: both
// outlive everything they were built from (the evaluator used to keep a raw pointer to the model).
TEST(Ownership, EvaluatorAndSamplerOutliveTheirSources) {
  std::shared_ptr<const ModelEvaluator> shared;
  double expected[3];
  const Vec3 wi = direction(30, 0.4), wo = direction(40, 2.0);
  {
    Model m = testing::make_model(testing::six_slices(), /*peaked=*/true);
    const ModelEvaluator reference(m);  // a copy of m
    reference.eval(wi, wo, expected);
    shared = std::make_shared<const ModelEvaluator>(std::move(m));
    m = Model{};  // the caller's model is gone
  }
  double rgb[3];
  shared->eval(wi, wo, rgb);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(rgb[c], expected[c]);
  BrdfSampler sampler = make_model_sampler(shared);
  ModelEvaluator moved = ModelEvaluator(shared->shared_model());
  shared.reset();  // the sampler holds the last reference
  int valid = 0;
  for (int k = 0; k < 64; ++k) {
    const BrdfSample s = sampler.sample(wo, (k + 0.5) / 64.0, std::fmod(k * 0.618, 1.0));
    if (!s.valid) continue;
    ++valid;
    EXPECT_GT(s.pdf, 0.0);
    EXPECT_NEAR(sampler.sample_pdf(s.wi, wo), s.pdf, 1e-12 * s.pdf);
  }
  EXPECT_GT(valid, 32);
  const ModelEvaluator after_move = std::move(moved);
  after_move.eval(wi, wo, rgb);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(rgb[c], expected[c]);
}

}  // namespace
}  // namespace cbrdf
