// SPDX-License-Identifier: MIT
// The Frank copula in the paper's sign convention (theta_paper = -t with t the standard parameter).
//
// With t = -theta, a = 1 - e^{-t}, r(u) = (1 - e^{-tu}) / a:
//   phi(u) = -log r(u),  psi(s) = -log(1 - a e^{-s}) / t,
//   psi^{(k)}(s) = (-1)^k Li_{1-k}(w) / t with w = a e^{-s}: Li_0 = w/(1-w), Li_{-1} = w/(1-w)^2,
//   Li_{-2} = w(1+w)/(1-w)^3, and w = h = prod_i (1 - e^{-t u_i}) / a^2 at s = sum phi(u_i), so
//   c(u) = (t/a)^2 (1+h)/(1-h)^3 e^{-t(u1+u2+u3)}.
//
// Domain, 3-D: psi generates a 3-D copula iff it is 3-monotone (McNeil & Neslehova 2009), i.e.
// (-1)^k psi^{(k)} >= 0 for k <= 3. For t > 0 psi is the Laplace transform of the logarithmic
// distribution, hence completely monotone; t = 0 is e^{-s}. For t < 0: a < 0, w in [a, 0), and
// (-1)^k psi^{(k)} = Li_{1-k}(w)/t; w/t > 0 and (1-w) > 0, so k = 1, 2 are positive and k = 3 has
// the sign of 1 + w, whose minimum over s >= 0 is 1 + a = 2 - e^{-t}: >= 0 iff -t <= ln 2. So the
// paper's domain is theta <= ln 2; beyond it the density is negative near u = (1,1,1).
//
// Stability: r = u E(-tu)/E(-t) with E(x) = expm1(x)/x (no 0/0 at t -> 0, no underflow of tu);
// near r = 1, phi = -log1p(-m) with m = 1 - r = (1-u) e^{-tu} E(-t(1-u))/E(-t) kept in logs;
// 1 - w = -expm1(-s) + e^{-t-s} (both >= 0) for t > 0; 1 + w = (1+a) - a(-expm1(-s)) for t < 0.
// There is no series switch: every factor above is accurate for all t, including t = 0.
#include <algorithm>
#include <cmath>

#include "copula/numerics.h"
#include "copula/registry.h"

namespace cbrdf::internal {
namespace {

// log(1 - w) and log|1 + w| for w = a e^{-s}.
struct FrankW {
  double s, w, log_1mw, log_1pw;
};

FrankW frank_w(double s, double log_s, double t) {
  FrankW r{};
  r.s = s;
  const double a = -std::expm1(-t);
  r.w = a * std::exp(-r.s);
  const double log_m = log1mexp_neg(log_s);  // m = 1 - e^{-s}, accurate even when s underflows
  if (t > 0 && r.w > 0.5) {
    r.log_1mw = log_add_exp(-t - r.s, log_m);  // 1 - w = e^{-t-s} + (1 - e^{-s})
  } else {
    r.log_1mw = std::log1p(-r.w);
  }
  if (t < 0 && r.w < -0.5) {
    // 1 + w = (1 + a) - a m, with 1 + a = 2 - e^{-t} = -2 expm1(-t - ln 2) >= 0 in the domain;
    // ln 2 in two parts so that theta = ln 2 (as a double) gives its tiny positive value.
    const double one_p_a = -2.0 * std::expm1((-t - kLn2Hi) - kLn2Lo);
    r.log_1pw = std::log(std::max(0.0, one_p_a - a * std::exp(log_m)));
  } else {
    r.log_1pw = std::log1p(r.w);
  }
  return r;
}

class FrankCopula final : public Copula {
 public:
  CopulaFamily family() const override { return CopulaFamily::kFrank; }
  Domain domain() const override { return {-kInf, kLn2, false, true, 0.0}; }

  double log_density(double u1, double u2, double u3, double theta) const override {
    if (!in_domain(theta) || !unit(u1) || !unit(u2) || !unit(u3)) return kNaN;
    const double t = -theta;
    double s = 0;
    const double log_s = log_sum_of(phi(u1, t), phi(u2, t), phi(u3, t), &s);
    const FrankW w = frank_w(s, log_s, t);
    return -2.0 * std::log(expm1_ratio(-t)) + w.log_1pw - 3.0 * w.log_1mw - t * (u1 + u2 + u3);
  }

  double log_generator(double u, double theta) const override {
    if (!in_domain(theta) || !unit(u)) return kNaN;
    return phi(u, -theta).log;
  }

  double log_abs_generator_derivative(double u, double theta) const override {
    if (!in_domain(theta) || !unit(u)) return kNaN;
    const double t = -theta;
    if (u == 0.0) return kInf;
    // |phi'(u)| = t e^{-tu} / (1 - e^{-tu}) = e^{-tu} / (u E(-tu)).
    return -t * u - std::log(u) - std::log(expm1_ratio(-t * u));
  }

  FastPath prepare_fast_path(double theta) const override {
    const double t = -theta;
    return {theta, {std::log(expm1_ratio(-t)), -std::expm1(-t), std::exp(-t), t}};
  }

  double prepared_third_derivative(double s, const FastPath& p) const override {
    // log|psi'''(s)| = log(a/t) - s + log((1+w)/(1-w)^3), w = a e^{-s}, from one expm1 or exp.
    if (!in_domain(p.theta) || !(s >= 0.0)) return kNaN;
    if (s == kInf) return -kInf;
    const double a = p.k[1], t = p.k[3];
    double e, m;  // e^{-s} and 1 - e^{-s}, each accurate
    if (s < 1.0) {
      m = -std::expm1(-s);
      e = 1.0 - m;
    } else {
      e = std::exp(-s);
      m = 1.0 - e;
    }
    const double w = a * e;
    const double one_m_w = t > 0 ? m + p.k[2] * e : 1.0 - w;
    const double one_p_w = 1.0 + w;
    if (one_m_w < 1e-100 || one_p_w < 0.5) {  // extreme corner or near theta = ln 2
      return log_abs_inverse_derivative(3, std::log(s), p.theta);
    }
    return p.k[0] - s + std::log(one_p_w / (one_m_w * one_m_w * one_m_w));
  }

  double log_abs_inverse_derivative(int k, double log_s, double theta) const override {
    if (!in_domain(theta) || k < 0 || k > 3 || std::isnan(log_s)) return kNaN;
    const double t = -theta;
    const FrankW w = frank_w(std::exp(log_s), log_s, t);
    const double log_e = std::log(expm1_ratio(-t));  // log(a / t)
    switch (k) {
      case 0:  // psi = -log(1-w)/t = (w/t) G(-w)
        if (std::abs(w.w) < 0.5) return log_e - w.s + std::log(log1p_ratio(-w.w));
        return std::log(-w.log_1mw / t);
      case 1:
        return log_e - w.s - w.log_1mw;
      case 2:
        return log_e - w.s - 2.0 * w.log_1mw;
      default:
        return log_e - w.s + w.log_1pw - 3.0 * w.log_1mw;
    }
  }

 protected:
  double tail_ratio(double log_x, double) const override { return std::exp(-std::exp(log_x)); }

 private:
  static Phi phi(double u, double t) {
    if (u == 0.0) return {kInf, kInf};
    if (u == 1.0) return {0.0, -kInf};
    const double log_e_t = std::log(expm1_ratio(-t));
    const double log_r = std::log(u) + std::log(expm1_ratio(-t * u)) - log_e_t;
    if (log_r < -kLn2) return {-log_r, std::log(-log_r)};
    // r >= 1/2: phi = -log1p(-m), m = 1 - r, computed without forming r.
    const double v = 1.0 - u;
    const double log_m = std::log(v) - t * u + std::log(expm1_ratio(-t * v)) - log_e_t;
    const double m = std::exp(log_m);
    const double g = log1p_ratio(-m);
    return {m * g, log_m + std::log(g)};
  }
};

}  // namespace

const Copula& frank_copula() {
  static const FrankCopula instance;
  return instance;
}

}  // namespace cbrdf::internal
