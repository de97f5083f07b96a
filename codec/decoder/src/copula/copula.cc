// SPDX-License-Identifier: MIT
// Family-independent parts of Copula: everything expressed through log phi, log|phi'| and
// log|psi^{(k)}|, so that each family only supplies those (plus a robust log_density).
#include "copula/copula.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "copula/numerics.h"
#include "copula/registry.h"

namespace cbrdf {

using internal::kInf;

bool Copula::Domain::contains(double theta) const {
  if (std::isnan(theta)) return false;
  const bool above = lo_inclusive ? theta >= lo : theta > lo;
  const bool below = hi_inclusive ? theta <= hi : theta < hi;
  return above && below;
}

Status Copula::check_parameter(double theta) const {
  if (in_domain(theta)) return ok_status();
  const Domain d = domain();
  return error(ErrorCode::kInvalidArgument,
               std::string(family_name(family())) + " copula parameter " + std::to_string(theta) +
                   " is outside its 3-D domain " + (d.lo_inclusive ? "[" : "(") +
                   std::to_string(d.lo) + ", " + std::to_string(d.hi) +
                   (d.hi_inclusive ? "]" : ")"));
}

double Copula::density(double u1, double u2, double u3, double theta) const {
  return std::exp(log_density(u1, u2, u3, theta));  // NaN stays NaN, -inf gives 0
}

double Copula::cdf(double u1, double u2, double u3, double theta) const {
  if (!in_domain(theta) || !unit(u1) || !unit(u2) || !unit(u3)) return kNaN;
  if (u1 == 0.0 || u2 == 0.0 || u3 == 0.0) return 0.0;
  const double log_s = internal::log_sum_exp3(log_generator(u1, theta), log_generator(u2, theta),
                                              log_generator(u3, theta));
  return std::exp(log_abs_inverse_derivative(0, log_s, theta));
}

double Copula::d_log_density_dtheta(double u1, double u2, double u3, double theta) const {
  if (!in_domain(theta) || !unit(u1) || !unit(u2) || !unit(u3)) return kNaN;
  const Domain d = domain();
  const double h = 1e-3 * std::max(1.0, std::abs(theta));
  auto f = [&](double x) { return log_density(u1, u2, u3, x); };
  if (d.contains(theta - 2 * h) && d.contains(theta + 2 * h)) {
    const double d1 = (f(theta + h) - f(theta - h)) / (2 * h);
    const double d2 = (f(theta + 2 * h) - f(theta - 2 * h)) / (4 * h);
    return (4 * d1 - d2) / 3;  // error O(h^4)
  }
  // One-sided second-order differences toward the inside, then one Richardson step.
  const double dir = d.contains(theta + 4 * h) ? 1.0 : -1.0;
  const double f0 = f(theta);
  auto one_sided = [&](double step) {
    return dir * (-3 * f0 + 4 * f(theta + dir * step) - f(theta + 2 * dir * step)) / (2 * step);
  };
  return (4 * one_sided(h) - one_sided(2 * h)) / 3;  // error O(h^3)
}

double Copula::generator(double u, double theta) const {
  return std::exp(log_generator(u, theta));
}

double Copula::generator_inverse(double s, double theta) const {
  if (!in_domain(theta) || !(s >= 0.0)) return kNaN;
  return std::exp(log_abs_inverse_derivative(0, std::log(s), theta));
}

double Copula::cdf2(double u1, double u2, double theta) const {
  return cdf(u1, u2, 1.0, theta);
}

namespace {
// Keeps a coordinate off the boundary for quantities that have no limit there.
double interior(double u) {
  return std::clamp(u, std::numeric_limits<double>::min(), 1.0 - 0x1p-53);
}
}  // namespace

double Copula::density2(double u1, double u2, double theta) const {
  if (!in_domain(theta) || !unit(u1) || !unit(u2)) return kNaN;
  u1 = interior(u1);
  u2 = interior(u2);
  const double log_s = internal::log_add_exp(log_generator(u1, theta), log_generator(u2, theta));
  return std::exp(log_abs_inverse_derivative(2, log_s, theta) +
                  log_abs_generator_derivative(u1, theta) +
                  log_abs_generator_derivative(u2, theta));
}

double Copula::conditional2(double u2, double u1, double theta) const {
  if (!in_domain(theta) || !unit(u1) || !unit(u2)) return kNaN;
  if (u2 == 0.0) return 0.0;
  if (u2 == 1.0) return 1.0;
  const double l1 = log_generator(u1, theta);
  const double l2 = log_generator(u2, theta);
  if (l1 == kInf) return tail_ratio(l2, theta);
  const double log_s = internal::log_add_exp(l1, l2);
  const double r = std::exp(log_abs_inverse_derivative(1, log_s, theta) -
                            log_abs_inverse_derivative(1, l1, theta));
  return std::clamp(r, 0.0, 1.0);
}

double Copula::conditional3(double u3, double u1, double u2, double theta) const {
  if (!in_domain(theta) || !unit(u1) || !unit(u2) || !unit(u3)) return kNaN;
  if (u3 == 0.0) return 0.0;
  if (u3 == 1.0) return 1.0;
  const double l12 = internal::log_add_exp(log_generator(u1, theta), log_generator(u2, theta));
  const double l3 = log_generator(u3, theta);
  if (l12 == kInf) return tail_ratio(l3, theta);
  const double log_s = internal::log_add_exp(l12, l3);
  const double r = std::exp(log_abs_inverse_derivative(2, log_s, theta) -
                            log_abs_inverse_derivative(2, l12, theta));
  return std::clamp(r, 0.0, 1.0);
}

namespace {
// Solves cdf(v) = p on [0, 1] for a non-decreasing cdf with derivative pdf: Newton steps kept
// inside a shrinking bracket, bisection when a step leaves it.
template <typename Cdf, typename Pdf>
double invert_monotone(double p, Cdf cdf, Pdf pdf) {
  if (std::isnan(p)) return p;
  if (p <= 0.0) return 0.0;
  if (p >= 1.0) return 1.0;
  double lo = 0.0, hi = 1.0, v = p;
  for (int it = 0; it < 200; ++it) {
    const double f = cdf(v) - p;
    if (std::isnan(f)) return f;
    if (f == 0.0) return v;
    (f > 0.0 ? hi : lo) = v;
    double next = v - f / pdf(v);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - v) <= 0x1p-52 * next || hi - lo <= 0x1p-52 * hi) return next;
    v = next;
  }
  return v;
}
}  // namespace

double Copula::conditional2_inverse(double p, double u1, double theta) const {
  if (!in_domain(theta) || !unit(u1)) return kNaN;
  const double l1 = log_generator(u1, theta);
  const double d1 = log_abs_inverse_derivative(1, l1, theta);
  auto cdf_v = [&](double v) { return conditional2(v, u1, theta); };
  auto pdf_v = [&](double v) {  // d/dv C(v | u1) = psi''(s) phi'(v) / psi'(phi(u1))
    const double lv = log_generator(v, theta);
    return std::exp(log_abs_inverse_derivative(2, internal::log_add_exp(l1, lv), theta) +
                    log_abs_generator_derivative(v, theta) - d1);
  };
  return invert_monotone(p, cdf_v, pdf_v);
}

double Copula::conditional3_inverse(double p, double u1, double u2, double theta) const {
  if (!in_domain(theta) || !unit(u1) || !unit(u2)) return kNaN;
  const double l12 = internal::log_add_exp(log_generator(u1, theta), log_generator(u2, theta));
  const double d2 = log_abs_inverse_derivative(2, l12, theta);
  auto cdf_v = [&](double v) { return conditional3(v, u1, u2, theta); };
  auto pdf_v = [&](double v) {  // psi'''(s) phi'(v) / psi''(phi(u1) + phi(u2))
    const double lv = log_generator(v, theta);
    return std::exp(log_abs_inverse_derivative(3, internal::log_add_exp(l12, lv), theta) +
                    log_abs_generator_derivative(v, theta) - d2);
  };
  return invert_monotone(p, cdf_v, pdf_v);
}

Copula::AxisTerm Copula::axis_term(double u, double theta) const {
  if (!in_domain(theta) || !unit(u)) return {kNaN, kNaN};
  return {generator(u, theta), log_abs_generator_derivative(u, theta)};
}

double Copula::log_abs_inverse_third_derivative(double s, double theta) const {
  if (!in_domain(theta) || !(s >= 0.0)) return kNaN;
  return log_abs_inverse_derivative(3, std::log(s), theta);
}

double Copula::prepared_third_derivative(double s, const FastPath& p) const {
  return log_abs_inverse_third_derivative(s, p.theta);
}

const Copula& copula_for(CopulaFamily family) {
  const CopulaFamilyRow* row = family_row(family);
  return row ? row->copula() : internal::independence_copula();
}

}  // namespace cbrdf
