// SPDX-License-Identifier: MIT
// The Joe copula: phi(u) = -log(1 - (1-u)^theta), psi(s) = 1 - (1 - e^{-s})^{1/theta}.
//
// Domain, 3-D: for theta >= 1 psi is the Laplace transform of a Sibuya(1/theta) variable,
// completely monotone, so a generator in every dimension; theta = 1 is independence. For
// theta < 1 (alpha = 1/theta > 1), psi''(s) = alpha z^{alpha-2}(1-z)(1 - alpha + alpha z) with
// z = 1 - e^{-s} is negative for small s: not 2-monotone.
//
// Derivatives, with z = 1 - e^{-s} and dz/ds = 1 - z:
//   psi'   = -alpha (1-z) z^{alpha-1}
//   psi''  =  alpha (1-z) z^{alpha-2} ((1-alpha) + alpha z)
//   psi''' = -alpha (1-z) z^{alpha-3} B(z), B = (1-alpha)(2-alpha) + (2alpha-1)(1-alpha) z +
//   alpha^2 z^2
// B(1) = 1 and B > 0 on [0, 1] for alpha in (0, 1]. In the density the factor 1 - z = e^{-s} =
// prod (1 - x_i) cancels exactly against the 1/(1 - x_i) of each phi'(u_i) (x_i = (1-u_i)^theta):
//   log c = 2 log theta + (alpha - 3) log z + log B(z) + (theta - 1) sum log(1 - u_i),
// which stays finite at u_i = 0. log z comes from log s (z ~ s when the x_i underflow at large
// theta), and phi = x G(-x) (G = log1p(x)/x) for small x, -log(-expm1(theta log1p(-u))) otherwise.
#include <cmath>

#include "copula/numerics.h"
#include "copula/registry.h"

namespace cbrdf::internal {
namespace {

// log z, z = 1 - e^{-s}, from log s.
double log_z(double log_s) {
  return log1mexp_neg(log_s);
}

class JoeCopula final : public Copula {
 public:
  CopulaFamily family() const override { return CopulaFamily::kJoe; }
  Domain domain() const override { return {1.0, kInf, true, false, 1.0}; }

  double log_density(double u1, double u2, double u3, double theta) const override {
    if (!in_domain(theta) || !unit(u1) || !unit(u2) || !unit(u3)) return kNaN;
    if (theta == 1.0) return 0.0;
    // phi'(1) = 0: density 0 on faces u_i = 1, +inf at the corner (upper tail dependence).
    const int ones = count_equal(u1, u2, u3, 1.0);
    if (ones == 3) return kInf;
    if (ones > 0) return -kInf;
    const double lv1 = std::log1p(-u1), lv2 = std::log1p(-u2), lv3 = std::log1p(-u3);
    const double lz =
        log_z(log_sum_exp3(log_phi(lv1, theta), log_phi(lv2, theta), log_phi(lv3, theta)));
    const double alpha = 1.0 / theta;
    return 2.0 * std::log(theta) + (alpha - 3.0) * lz + std::log(b3(std::exp(lz), theta)) +
           (theta - 1.0) * (lv1 + lv2 + lv3);
  }

  double log_generator(double u, double theta) const override {
    if (!in_domain(theta) || !unit(u)) return kNaN;
    return log_phi(std::log1p(-u), theta);
  }

  double log_abs_generator_derivative(double u, double theta) const override {
    if (!in_domain(theta) || !unit(u)) return kNaN;
    // |phi'(u)| = theta (1-u)^{theta-1} / (1 - (1-u)^theta)
    if (theta == 1.0) return -std::log(u);
    if (u == 1.0) return -kInf;
    const double lv = std::log1p(-u);
    return std::log(theta) + (theta - 1.0) * lv - std::log(-std::expm1(theta * lv));
  }

  FastPath prepare_fast_path(double theta) const override {
    return {theta, {1.0 / theta, std::log(1.0 / theta), 0, 0}};
  }

  double prepared_third_derivative(double s, const FastPath& p) const override {
    // log alpha - s + (alpha - 3) log z + log B(z), z = 1 - e^{-s}: expm1, log, log.
    const double theta = p.theta;
    if (!in_domain(theta) || !(s >= 0.0)) return kNaN;
    const double z = -std::expm1(-s);
    if (theta == 1.0 || !(z >= 1e-300)) {  // independence, or z too small for its log
      return log_abs_inverse_derivative(3, std::log(s), theta);
    }
    return p.k[1] - s + (p.k[0] - 3.0) * std::log(z) + std::log(b3(z, theta));
  }

  double log_abs_inverse_derivative(int k, double log_s, double theta) const override {
    if (!in_domain(theta) || k < 0 || k > 3 || std::isnan(log_s)) return kNaN;
    const double s = std::exp(log_s);
    if (theta == 1.0) return -s;
    const double lz = log_z(log_s);
    const double z = std::exp(lz);
    const double alpha = 1.0 / theta;
    const double one_m_alpha = (theta - 1.0) / theta;
    switch (k) {
      case 0:
        return std::log(-std::expm1(alpha * lz));
      case 1:
        return std::log(alpha) - s + (alpha - 1.0) * lz;
      case 2:
        return std::log(alpha) - s + (alpha - 2.0) * lz + std::log(one_m_alpha + alpha * z);
      default:
        return std::log(alpha) - s + (alpha - 3.0) * lz + std::log(b3(z, theta));
    }
  }

 protected:
  double tail_ratio(double log_x, double) const override { return std::exp(-std::exp(log_x)); }

 private:
  // log phi from log(1-u).
  static double log_phi(double log_v, double theta) {
    const double lx = theta * log_v;  // log x, x = (1-u)^theta
    const double x = std::exp(lx);
    if (x <= 0.5) return lx + std::log(log1p_ratio(-x));
    return std::log(-std::log(-std::expm1(lx)));
  }
  static double b3(double z, double theta) {
    const double alpha = 1.0 / theta;
    const double one_m_alpha = (theta - 1.0) / theta;
    const double two_m_alpha = (2.0 * theta - 1.0) / theta;
    return one_m_alpha * two_m_alpha + (2.0 * alpha - 1.0) * one_m_alpha * z +
           alpha * alpha * z * z;
  }
};

}  // namespace

const Copula& joe_copula() {
  static const JoeCopula instance;
  return instance;
}

}  // namespace cbrdf::internal
