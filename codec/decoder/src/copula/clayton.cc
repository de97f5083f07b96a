// SPDX-License-Identifier: MIT
// The Clayton copula: phi(u) = (u^{-theta} - 1)/theta, psi(s) = (1 + theta s)^{-1/theta},
//   c(u) = (1+theta)(1+2 theta) prod u_i^{-theta-1} (sum u_i^{-theta} - 2)^{-1/theta-3}.
//
// Domain, 3-D: for theta > 0 psi is the Laplace transform of a Gamma(1/theta) variable, hence
// completely monotone and a copula generator in every dimension; theta -> 0 gives e^{-s}
// (independence). Negative theta generates a 3-D copula for theta >= -1/(d-1) = -1/2 (psi =
// (1 + theta s)_+^{-1/theta} is d-monotone iff -1/theta >= d - 1), but it is excluded here: the
// generator is then not strict (phi(0) = -1/theta is finite), the density vanishes on the region
// sum phi(u_i) > -1/theta, and at -1/2 the copula is purely singular (psi''' = 0). Weak negative
// dependence is what the Frank family's (0, ln 2] already offers.
//
// Stability: with L = -log u, phi = L E(theta L) (E(x) = expm1(x)/x), and
// sum u_i^{-theta} - 2 = 1 + theta s = 1 + sum expm1(theta L_i): a sum of non-negative terms. The
// exponent 1/theta multiplies log1p(theta s), kept as s G(theta s) (G = log1p(x)/x) so that
// theta -> 0 is exact; when theta s overflows, log(theta s) is taken from log s directly.
#include <cmath>

#include "copula/numerics.h"
#include "copula/registry.h"

namespace cbrdf::internal {
namespace {

// log1p(theta s) and log1p(theta s) / theta, from log s.
struct ClaytonT {
  double log1p_ts, log1p_ts_over_theta;
};

ClaytonT clayton_t(double s, double log_s, double theta) {
  if (theta == 0.0) return {0.0, s};
  const double lt = std::log(theta) + log_s;  // log(theta s)
  if (lt > 30.0) {
    const double l = lt + std::log1p(std::exp(-lt));
    return {l, l / theta};
  }
  const double y = theta * s;
  return {std::log1p(y), s * log1p_ratio(y)};
}

class ClaytonCopula final : public Copula {
 public:
  CopulaFamily family() const override { return CopulaFamily::kClayton; }
  Domain domain() const override { return {0.0, kInf, true, false, 0.0}; }

  double log_density(double u1, double u2, double u3, double theta) const override {
    if (!in_domain(theta) || !unit(u1) || !unit(u2) || !unit(u3)) return kNaN;
    if (theta == 0.0) return 0.0;
    const double log_c0 = std::log1p(theta) + std::log1p(2.0 * theta);
    const int zeros = count_equal(u1, u2, u3, 0.0);
    if (zeros > 0) {
      // Along the diagonal of the k zero coordinates the density goes like x^{(theta+1)k-1-3theta}.
      if (zeros == 1) return -kInf;
      if (zeros == 3) return kInf;
      if (theta != 1.0) return theta < 1.0 ? kInf : -kInf;
      const double u = u1 + u2 + u3;                   // the one non-zero coordinate
      return log_c0 - 2.0 * std::log(u) - 4.0 * kLn2;  // theta = 1: 6/16 u^{-2}
    }
    const double sum_l = -(std::log(u1) + std::log(u2) + std::log(u3));
    double s = 0;
    const double log_s = log_sum_of(phi(u1, theta), phi(u2, theta), phi(u3, theta), &s);
    const ClaytonT t = clayton_t(s, log_s, theta);
    return log_c0 + (theta + 1.0) * sum_l - t.log1p_ts_over_theta - 3.0 * t.log1p_ts;
  }

  double log_generator(double u, double theta) const override {
    if (!in_domain(theta) || !unit(u)) return kNaN;
    return phi(u, theta).log;
  }

  double log_abs_generator_derivative(double u, double theta) const override {
    if (!in_domain(theta) || !unit(u)) return kNaN;
    return -(theta + 1.0) * std::log(u);  // |phi'(u)| = u^{-theta-1}
  }

  FastPath prepare_fast_path(double theta) const override {
    return {theta, {std::log1p(theta) + std::log1p(2.0 * theta), 0, 0, 0}};
  }

  double prepared_third_derivative(double s, const FastPath& p) const override {
    // (1+theta)(1+2theta)(1 + theta s)^{-1/theta-3}: one log1p.
    const double theta = p.theta;
    if (!in_domain(theta) || !(s >= 0.0)) return kNaN;
    const double y = theta * s;
    if (!std::isfinite(y)) return log_abs_inverse_derivative(3, std::log(s), theta);
    const double l = std::log1p(y);
    const double l_over_theta = y < 1e-200 ? s : l / theta;  // = s (1 - y/2 + ...)
    return p.k[0] - l_over_theta - 3.0 * l;
  }

  double log_abs_inverse_derivative(int k, double log_s, double theta) const override {
    if (!in_domain(theta) || k < 0 || k > 3 || std::isnan(log_s)) return kNaN;
    // |psi^{(k)}(s)| = prod_{j<k} (1 + j theta) (1 + theta s)^{-1/theta - k}.
    const ClaytonT t = clayton_t(std::exp(log_s), log_s, theta);
    double r = -t.log1p_ts_over_theta - k * t.log1p_ts;
    for (int j = 1; j < k; ++j) r += std::log1p(j * theta);
    return r;
  }

 protected:
  double tail_ratio(double log_x, double theta) const override {
    return theta == 0.0 ? std::exp(-std::exp(log_x)) : 1.0;
  }

 private:
  static Phi phi(double u, double theta) {
    if (u == 0.0) return {kInf, kInf};
    if (u == 1.0) return {0.0, -kInf};
    const double l = -std::log(u);
    const double x = theta * l;
    if (x < 700.0) {
      const double e = expm1_ratio(x);
      return {l * e, std::log(l) + std::log(e)};
    }
    return {kInf, x - std::log(theta) + std::log1p(-std::exp(-x))};
  }
};

}  // namespace

const Copula& clayton_copula() {
  static const ClaytonCopula instance;
  return instance;
}

}  // namespace cbrdf::internal
