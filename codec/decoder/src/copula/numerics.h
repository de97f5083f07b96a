// SPDX-License-Identifier: MIT
// Small numerical helpers shared by the copula families (internal).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

namespace cbrdf::internal {

inline constexpr double kInf = std::numeric_limits<double>::infinity();
inline constexpr double kLn2 = 0.69314718055994530942;
// ln 2 = kLn2Hi + kLn2Lo to about 1e-33, for arguments that cancel against ln 2.
inline constexpr double kLn2Hi = 0x1.62e42fefa39efp-1;
inline constexpr double kLn2Lo = 0x1.abc9e3b39803fp-56;

// E(x) = expm1(x) / x, E(0) = 1: accurate for all x, never 0/0 (tiny x gives exactly 1).
inline double expm1_ratio(double x) {
  return x == 0.0 ? 1.0 : std::expm1(x) / x;
}
// G(x) = log1p(x) / x, G(0) = 1, for x >= -1.
inline double log1p_ratio(double x) {
  return x == 0.0 ? 1.0 : std::log1p(x) / x;
}

// log(e^a + e^b) without overflow; handles infinities.
inline double log_add_exp(double a, double b) {
  const double m = std::max(a, b);
  if (m == -kInf || m == kInf) return m;
  return m + std::log1p(std::exp(std::min(a, b) - m));
}
inline double log_sum_exp3(double a, double b, double c) {
  const double m = std::max({a, b, c});
  if (m == -kInf || m == kInf) return m;
  return m + std::log(std::exp(a - m) + std::exp(b - m) + std::exp(c - m));
}

// log(1 - e^{-s}) from log s: exact as s -> 0 (even when s underflows) and as s -> inf (where
// 1 - e^{-s} rounds to 1 but its log is -e^{-s}).
inline double log1mexp_neg(double log_s) {
  const double s = std::exp(log_s);
  if (s > kLn2) return std::log1p(-std::exp(-s));
  return log_s + std::log(expm1_ratio(-s));
}

// phi(u) and log phi(u) together: the sum of the phi (accurate to a few ulp) is the better s where
// it is a normal double; the log-sum-exp of the log phi covers overflow and underflow.
struct Phi {
  double value, log;
};
inline double log_sum_of(const Phi& a, const Phi& b, const Phi& c, double* s) {
  *s = a.value + b.value + c.value;
  if (std::isnormal(*s) && std::isfinite(*s)) return std::log(*s);
  const double log_s = log_sum_exp3(a.log, b.log, c.log);
  *s = std::exp(log_s);
  return log_s;
}

inline int count_equal(double u1, double u2, double u3, double v) {
  return int(u1 == v) + int(u2 == v) + int(u3 == v);
}

}  // namespace cbrdf::internal
