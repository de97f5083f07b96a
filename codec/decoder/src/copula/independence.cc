// SPDX-License-Identifier: MIT
// The independence copula: c = 1, phi(u) = -log u, psi(s) = e^{-s}. Its only parameter is 0.
#include <cmath>

#include "copula/numerics.h"
#include "copula/registry.h"

namespace cbrdf::internal {
namespace {

class IndependenceCopula final : public Copula {
 public:
  CopulaFamily family() const override { return CopulaFamily::kIndependence; }
  Domain domain() const override { return {0.0, 0.0, true, true, 0.0}; }

  double log_density(double u1, double u2, double u3, double theta) const override {
    if (!in_domain(theta) || !unit(u1) || !unit(u2) || !unit(u3)) return kNaN;
    return 0.0;
  }
  double log_generator(double u, double theta) const override {
    if (!in_domain(theta) || !unit(u)) return kNaN;
    return std::log(-std::log(u));  // -inf at u = 1, +inf at u = 0
  }
  double log_abs_generator_derivative(double u, double theta) const override {
    if (!in_domain(theta) || !unit(u)) return kNaN;
    return -std::log(u);
  }
  double log_abs_inverse_derivative(int k, double log_s, double theta) const override {
    if (!in_domain(theta) || k < 0 || k > 3 || std::isnan(log_s)) return kNaN;
    return -std::exp(log_s);
  }

 protected:
  double tail_ratio(double log_x, double) const override { return std::exp(-std::exp(log_x)); }
};

}  // namespace

const Copula& independence_copula() {
  static const IndependenceCopula instance;
  return instance;
}

}  // namespace cbrdf::internal
