// SPDX-License-Identifier: MIT
// The Gumbel-Hougaard copula: phi(u) = (-log u)^theta, psi(s) = exp(-s^{1/theta}).
//
// Domain, 3-D: for theta >= 1 psi is the Laplace transform of a positive stable(1/theta) variable,
// completely monotone, so a generator in every dimension; theta = 1 is independence. For
// theta < 1, psi''(s) = alpha s^{alpha-2} e^{-y} y (alpha y + 1 - alpha) with alpha = 1/theta > 1
// and y = s^alpha is negative for small s: not even 2-monotone.
//
// Derivatives: psi^{(k)}(s) = (-1)^k e^{-y} s^{-k} P_k(y) with P_{k+1} = (alpha y + k) P_k -
// alpha y P_k', giving P_1 = alpha y, P_2 = alpha y (alpha y + 1 - alpha),
// P_3 = alpha y (alpha^2 y^2 + 3 alpha (1-alpha) y + (1-alpha)(2-alpha)): all coefficients >= 0 on
// the domain, so no cancellation, and 1 - alpha = (theta-1)/theta is exact near theta = 1.
// Everything is computed from log s, because s = sum L_i^theta overflows for large theta while
// y = s^{1/theta} <= 3 max L_i stays moderate.
#include <cmath>

#include "copula/numerics.h"
#include "copula/registry.h"

namespace cbrdf::internal {
namespace {

class GumbelCopula final : public Copula {
 public:
  CopulaFamily family() const override { return CopulaFamily::kGumbel; }
  Domain domain() const override { return {1.0, kInf, true, false, 1.0}; }

  double log_density(double u1, double u2, double u3, double theta) const override {
    if (!in_domain(theta) || !unit(u1) || !unit(u2) || !unit(u3)) return kNaN;
    if (theta == 1.0) return 0.0;
    // On the boundary: phi'(1) = 0 (density 0 on faces u_i = 1), +inf at the corner (1,1,1)
    // (upper tail dependence); 0 on faces u_i = 0 and +inf along the diagonal of 2 or 3 zeros.
    const int ones = count_equal(u1, u2, u3, 1.0);
    const int zeros = count_equal(u1, u2, u3, 0.0);
    if (ones == 3) return kInf;
    if (ones > 0 || zeros == 1) return -kInf;
    if (zeros > 1) return kInf;
    const double l1 = -std::log(u1), l2 = -std::log(u2), l3 = -std::log(u3);
    const double ll1 = std::log(l1), ll2 = std::log(l2), ll3 = std::log(l3);
    const double log_s = log_sum_exp3(theta * ll1, theta * ll2, theta * ll3);
    const double log_y = log_s / theta;
    const double y = std::exp(log_y);
    return -y - 3.0 * log_s + log_y + std::log(q3(y, theta)) + 2.0 * std::log(theta) +
           (theta - 1.0) * (ll1 + ll2 + ll3) + (l1 + l2 + l3);
  }

  double log_generator(double u, double theta) const override {
    if (!in_domain(theta) || !unit(u)) return kNaN;
    return theta * std::log(-std::log(u));
  }

  double log_abs_generator_derivative(double u, double theta) const override {
    if (!in_domain(theta) || !unit(u)) return kNaN;
    // |phi'(u)| = theta L^{theta-1} / u, L = -log u.
    const double l = -std::log(u);
    if (theta == 1.0) return l;
    if (u == 0.0) return kInf;
    return std::log(theta) + (theta - 1.0) * std::log(l) + l;
  }

  FastPath prepare_fast_path(double theta) const override {
    return {theta, {1.0 / theta, std::log(1.0 / theta), 0, 0}};
  }

  double prepared_third_derivative(double s, const FastPath& p) const override {
    // -y - 3 log s + log(alpha y Q(y)), y = s^alpha: log, exp, log.
    const double theta = p.theta;
    if (!in_domain(theta) || !(s >= 0.0)) return kNaN;
    if (s == 0.0 || s == kInf) return log_abs_inverse_derivative(3, std::log(s), theta);
    const double log_s = std::log(s);
    const double log_y = p.k[0] * log_s;
    const double y = std::exp(log_y);
    return -y - 3.0 * log_s + p.k[1] + log_y + std::log(q3(y, theta));
  }

  double log_abs_inverse_derivative(int k, double log_s, double theta) const override {
    if (!in_domain(theta) || k < 0 || k > 3 || std::isnan(log_s)) return kNaN;
    if (log_s == kInf) return -kInf;
    if (log_s == -kInf) {  // s = 0: psi(0) = 1; |psi^{(k)}(0)| = inf for theta > 1
      if (k == 0) return 0.0;
      return theta == 1.0 ? 0.0 : kInf;
    }
    const double alpha = 1.0 / theta;
    const double one_m_alpha = (theta - 1.0) / theta;
    const double log_y = log_s / theta;
    const double y = std::exp(log_y);
    switch (k) {
      case 0:
        return -y;
      case 1:
        return -y - log_s + std::log(alpha) + log_y;
      case 2:
        return -y - 2.0 * log_s + std::log(alpha) + log_y + std::log(alpha * y + one_m_alpha);
      default:
        return -y - 3.0 * log_s + std::log(alpha) + log_y + std::log(q3(y, theta));
    }
  }

 protected:
  double tail_ratio(double log_x, double theta) const override {
    return theta == 1.0 ? std::exp(-std::exp(log_x)) : 1.0;
  }

 private:
  // P_3(y) / (alpha y) = alpha^2 y^2 + 3 alpha (1-alpha) y + (1-alpha)(2-alpha).
  static double q3(double y, double theta) {
    const double alpha = 1.0 / theta;
    const double one_m_alpha = (theta - 1.0) / theta;
    const double two_m_alpha = (2.0 * theta - 1.0) / theta;
    return alpha * alpha * y * y + 3.0 * alpha * one_m_alpha * y + one_m_alpha * two_m_alpha;
  }
};

}  // namespace

const Copula& gumbel_copula() {
  static const GumbelCopula instance;
  return instance;
}

}  // namespace cbrdf::internal
