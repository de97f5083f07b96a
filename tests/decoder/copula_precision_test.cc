// SPDX-License-Identifier: MIT
// Precision of the copula densities against independent higher-precision references.
//
// The references are written in long double (64-bit significand, and an exponent range to
// 1e+-4932, so e^{-t} for t up to 11000 and the products below neither underflow nor overflow) from
// forms chosen to be free of cancellation by construction, and deliberately different from the
// library's: the library works with expm1 ratios and log-sum-exp of log-generators in double; the
// references use the textbook closed forms with inclusion-exclusion sums of non-negative terms.
// The Frank reference is itself checked against the paper's Eq. 13 in long double where that form
// is accurate (moderate |theta|), and all densities are checked against their CDFs in
// copula_test.cc, so a shared derivation error would not go unnoticed.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "copula/copula.h"

namespace cbrdf {
namespace {

using LD = long double;
constexpr double kLn2 = 0.69314718055994530942;
// ln 2 = kLn2Hi + kLn2Lo to about 1e-33 (a long double ln 2 alone is off by up to 3e-20, which is
// the whole value of 2 - e^{-t} near theta = ln 2).
constexpr LD kLn2Hi = 0x1.62e42fefa39efp-1;
constexpr LD kLn2Lo = 0x1.abc9e3b39803fp-56;

LD log_sum_exp(const LD* v, int n) {
  LD m = v[0];
  for (int i = 1; i < n; ++i) m = std::max(m, v[i]);
  if (std::isinf(m)) return m;
  LD s = 0;
  for (int i = 0; i < n; ++i) s += expl(v[i] - m);
  return m + logl(s);
}

// Standard Frank (t = -theta_paper): c = (t/a)^2 (1+h)/(1-h)^3 e^{-t sum u}, h = prod b_i / a^2,
// b_i = 1 - e^{-t u_i}, a = 1 - e^{-t}. With d_i = 1 - b_i/a = e^{-t u_i}(1 - e^{-t(1-u_i)})/a >= 0
// and r_i = b_i / a: h = a (1 - D), D = d1 + r1 d2 + r1 r2 d3 (non-negative terms), so
// 1 - h = e^{-t} + a D and, for t < 0, 1 + h = (1 + a) + |a| D: no cancellation anywhere.
LD frank_ref_log(const double u[3], double theta) {
  const LD t = -LD(theta);
  if (t == 0) return 0;
  const LD a = -expm1l(-t);
  LD b[3], d[3], r[3];
  for (int i = 0; i < 3; ++i) {
    const LD ui = u[i];
    b[i] = -expm1l(-t * ui);
    r[i] = b[i] / a;
    d[i] = expl(-t * ui) * -expm1l(-t * (1 - ui)) / a;
  }
  const LD big_d = d[0] + r[0] * d[1] + r[0] * r[1] * d[2];
  const LD h = a * r[0] * r[1] * r[2];
  const LD one_m_h = t > 0 ? expl(-t) + a * big_d : 1 - h;
  // 1 + a = 2 - e^{-t} = -2 expm1(-t - ln 2): no cancellation against 2 near theta = ln 2.
  const LD one_p_h = t > 0 ? 1 + h : -2 * expm1l((-t - kLn2Hi) - kLn2Lo) - a * big_d;
  return 2 * logl(t / a) + logl(one_p_h) - 3 * logl(one_m_h) - t * (LD(u[0]) + u[1] + u[2]);
}

// The paper's Eq. 13 (signed), only accurate at moderate |alpha|.
LD frank_paper_eq13(const double u[3], LD alpha) {
  auto g = [&](LD x) { return expm1l(alpha * x); };
  const LD g1 = g(1), g1s = g1 * g1, guvy = g(u[0]) * g(u[1]) * g(u[2]);
  const LD den = g1s + guvy;
  return alpha * alpha * g1s * (1 + g(LD(u[0]) + u[1] + u[2])) * (g1s - guvy) / (den * den * den);
}

// Clayton: log c = log((1+th)(1+2th)) + (th+1) sum L - (1/th + 3) log T, T = 1 + sum expm1(th L).
LD clayton_ref_log(const double u[3], double theta) {
  const LD th = theta;
  if (th == 0) return 0;
  LD sum_l = 0, x[3];
  bool huge = false;
  for (int i = 0; i < 3; ++i) {
    const LD l = -logl(LD(u[i]));
    sum_l += l;
    x[i] = th * l;
    huge = huge || x[i] > 11000;
  }
  LD log_t, log_t_over_th;
  if (huge) {  // T = sum e^{x_i} - 2 with some e^{x_i} beyond the long double range: 2 is nothing
    log_t = log_sum_exp(x, 3);
    log_t_over_th = log_t / th;
  } else {
    const LD m = expm1l(x[0]) + expm1l(x[1]) + expm1l(x[2]);
    log_t = log1pl(m);
    log_t_over_th = log_t / th;
  }
  return log1pl(th) + log1pl(2 * th) + (th + 1) * sum_l - log_t_over_th - 3 * log_t;
}

// Gumbel: c = e^{-y} s^{-3} (y^3 + 3(th-1) y^2 + (th-1)(2th-1) y) prod L_i^{th-1} / u_i.
LD gumbel_ref_log(const double u[3], double theta) {
  const LD th = theta;
  LD l[3], tl[3], sum_ll = 0, sum_l = 0;
  for (int i = 0; i < 3; ++i) {
    l[i] = -logl(LD(u[i]));
    tl[i] = th * logl(l[i]);
    sum_ll += logl(l[i]);
    sum_l += l[i];
  }
  const LD log_s = log_sum_exp(tl, 3);
  const LD y = expl(log_s / th);
  const LD poly = y * y * y + 3 * (th - 1) * y * y + (th - 1) * (2 * th - 1) * y;
  return -y - 3 * log_s + logl(poly) + (th - 1) * sum_ll + sum_l;
}

// Joe: c = prod v_i^{th-1} z^{1/th-3} (z^2 - (th-1)(th-2) z + (th-1)(2th-1)), v = 1-u, x = v^th,
// z = 1 - prod(1 - x_i) = x1 + q1 x2 + q1 q2 x3 with q_i = 1 - x_i = -expm1(th log v_i).
LD joe_ref_log(const double u[3], double theta) {
  const LD th = theta;
  LD lv[3], lx[3], x[3], q[3], sum_lv = 0;
  for (int i = 0; i < 3; ++i) {
    lv[i] = log1pl(-LD(u[i]));
    lx[i] = th * lv[i];
    x[i] = expl(lx[i]);
    q[i] = -expm1l(lx[i]);
    sum_lv += lv[i];
  }
  LD log_z;
  if (std::max({lx[0], lx[1], lx[2]}) < -11000) {
    log_z = log_sum_exp(lx, 3);  // every x_i < e^{-11000}: z = sum x_i to long double precision
  } else {
    log_z = logl(x[0] + q[0] * x[1] + q[0] * q[1] * x[2]);
  }
  const LD z = expl(log_z);
  const LD poly = z * z - (th - 1) * (th - 2) * z + (th - 1) * (2 * th - 1);
  return (th - 1) * sum_lv + (1 / th - 3) * log_z + logl(poly);
}

const std::vector<double> kInteriorU = {1e-300, 1e-12, 1e-6, 0.1,        0.3,
                                        0.5,    0.7,   0.9,  1.0 - 1e-6, 1.0 - 1e-12};

// Worst relative error |c/c_ref - 1| (via the log difference) over the interior grid.
struct Worst {
  double density = 0;  // relative error of c where c is a normal double
  double log = 0;      // relative error of log c elsewhere
};

Worst worst_error(CopulaFamily f, double theta, LD (*ref)(const double*, double)) {
  const Copula& c = copula_for(f);
  double worst = 0, worst_log = 0;
  for (double a : kInteriorU)
    for (double b : kInteriorU)
      for (double d : kInteriorU) {
        const double u[3] = {a, b, d};
        const double got = c.log_density(a, b, d, theta);
        const LD want = ref(u, theta);
        EXPECT_FALSE(std::isnan(got))
            << family_name(f) << " theta=" << theta << " u=" << a << "," << b << "," << d;
        if (std::isinf(want) || std::isinf(got)) {
          EXPECT_EQ(double(want), got)
              << family_name(f) << " theta=" << theta << " u=" << a << "," << b << "," << d;
          continue;
        }
        // Relative error of the density where it is a normal double; beyond that (it underflows
        // or overflows in double) the relative error of log c, which is what log_density offers.
        const bool representable = want > -708 && want < 709;
        const double err = representable ? std::abs(std::expm1(double(LD(got) - want)))
                                         : double(std::abs((LD(got) - want) / want));
        double& w = representable ? worst : worst_log;
        if (err > w) w = err;
        EXPECT_LE(err, 1e-9) << family_name(f) << " theta=" << theta << " u=" << a << "," << b
                             << "," << d << " got " << got << " want " << double(want);
      }
  return {worst, worst_log};
}

void report(const char* family, const std::vector<double>& thetas, CopulaFamily f,
            LD (*ref)(const double*, double)) {
  for (double theta : thetas) {
    const Worst w = worst_error(f, theta, ref);
    std::printf(
        "  %-8s theta = %-22.17g worst relative error of c %.3g, of log c (c beyond double) %.3g\n",
        family, theta, w.density, w.log);
  }
}

TEST(CopulaPrecision, FrankReferenceAgreesWithPaperEq13AtModerateTheta) {
  // Validates the reference itself: Eq. 13 is exact algebra, accurate in long double here.
  for (double alpha : {-5.0, -1.0, -0.01, 0.01, 0.5, kLn2}) {
    for (double a : {0.05, 0.3, 0.5, 0.8, 0.99})
      for (double b : {0.1, 0.5, 0.95})
        for (double d : {0.2, 0.6, 0.999}) {
          const double u[3] = {a, b, d};
          const LD want = frank_paper_eq13(u, alpha);
          const LD got = expl(frank_ref_log(u, alpha));
          EXPECT_NEAR(double(got / want), 1.0, 1e-12) << "alpha=" << alpha;
        }
  }
}

TEST(CopulaPrecision, Frank) {
  report("frank",
         {0.0, 1e-300, -1e-300, 1e-12, -1e-12, 1e-6, -1e-6, 0.5, kLn2, -0.5, -1.0, -5.0, -20.0,
          -50.0, -300.0, -745.0, -1e4},
         CopulaFamily::kFrank, frank_ref_log);
}

TEST(CopulaPrecision, Clayton) {
  report("clayton", {0.0, 1e-300, 1e-12, 1e-6, 0.5, 1.0, 2.0, 5.0, 50.0, 300.0, 745.0, 1e4},
         CopulaFamily::kClayton, clayton_ref_log);
}

TEST(CopulaPrecision, Gumbel) {
  report("gumbel", {1.0, 1.0 + 1e-12, 1.0 + 1e-6, 1.5, 2.0, 5.0, 50.0, 300.0, 745.0, 1e4},
         CopulaFamily::kGumbel, gumbel_ref_log);
}

TEST(CopulaPrecision, Joe) {
  report("joe", {1.0, 1.0 + 1e-12, 1.0 + 1e-6, 1.5, 2.0, 5.0, 50.0, 300.0, 745.0, 1e4},
         CopulaFamily::kJoe, joe_ref_log);
}

}  // namespace
}  // namespace cbrdf
