// SPDX-License-Identifier: MIT
// Archimedean copula families in three dimensions: densities, CDFs, conditional distributions for
// sampling, and a per-axis fast path for fitting over a grid.
//
// An Archimedean copula is C(u) = psi(phi(u1) + phi(u2) + phi(u3)), with the generator phi:
// [0,1] -> [0,inf] decreasing, phi(1) = 0, and psi = phi^{-1}. Here phi is always the standard
// (non-negative) generator; the paper writes its Frank generator with the opposite sign, as
// ln((e^{theta t}-1)/(e^theta-1)) = -phi(t). The 3-D density is
//   c(u) = psi'''(s) phi'(u1) phi'(u2) phi'(u3),  s = phi(u1) + phi(u2) + phi(u3).
//
// Parameter conventions and 3-D domains (proofs in each family's source file):
//   independence  theta = 0 only; c = 1.
//   frank         the paper's sign: g_t = e^{theta t} - 1. theta < 0 positive dependence, theta = 0
//                 independence, 0 < theta <= ln 2 weak negative dependence. Domain (-inf, ln 2].
//                 (The standard Frank parameter is -theta.)
//   clayton       psi(s) = (1 + theta s)^{-1/theta}. Domain [0, inf), 0 = independence. Negative
//                 theta (valid in 3-D down to -1/2) is excluded on purpose: see clayton.cc.
//   gumbel        Gumbel-Hougaard, psi(s) = exp(-s^{1/theta}). Domain [1, inf), 1 = independence.
//   joe           psi(s) = 1 - (1 - e^{-s})^{1/theta}. Domain [1, inf), 1 = independence.
//
// Numerics: every function works in the log domain internally and is valid over the whole
// parameter domain (including |theta| up to 1e4 and tiny |theta|) and for u in [0,1]. log_density
// never returns NaN for u in [0,1]^3 and theta in the domain: it returns -inf where the density is
// 0 and +inf only where it is infinite. On the boundary of the cube, where some densities have no
// continuous extension (Clayton, Gumbel, Joe on faces and edges), the value is the limit along the
// coordinate direction for one coordinate at 0 or 1 and along the diagonal for several.
// Outside the domain, or for u outside [0,1] or NaN, every function returns NaN: check parameters
// first with in_domain() / check_parameter().
#pragma once

#include <limits>

#include "cbrdf/copula_family.h"
#include "cbrdf/status.h"

namespace cbrdf {

class Copula {
 public:
  // The valid parameter range in three dimensions, and the parameter giving independence.
  struct Domain {
    double lo = 0, hi = 0;
    bool lo_inclusive = true, hi_inclusive = true;
    double independence = 0;
    bool contains(double theta) const;
  };
  // Per-axis terms of the fast path: phi(u) and log|phi'(u)|.
  struct AxisTerm {
    double psi = 0;           // the generator phi(u)
    double log_abs_dpsi = 0;  // log|phi'(u)|
  };

  virtual ~Copula() = default;
  virtual CopulaFamily family() const = 0;
  virtual Domain domain() const = 0;
  bool in_domain(double theta) const { return domain().contains(theta); }
  // kInvalidArgument naming the family, the value and the valid range when theta is outside.
  Status check_parameter(double theta) const;

  // ---- The 3-D copula ----
  virtual double log_density(double u1, double u2, double u3, double theta) const = 0;
  // exp(log_density): 0 where log_density is -inf.
  double density(double u1, double u2, double u3, double theta) const;
  double cdf(double u1, double u2, double u3, double theta) const;
  // d/dtheta log c(u; theta) by a Richardson-extrapolated difference (one-sided at the domain's
  // ends). Relative accuracy about 1e-8; meaningful where the density is positive and finite.
  double d_log_density_dtheta(double u1, double u2, double u3, double theta) const;

  // ---- Generator phi and its inverse psi ----
  double generator(double u, double theta) const;          // phi(u); may overflow to +inf
  double generator_inverse(double s, double theta) const;  // psi(s), s in [0, inf]
  // log phi(u), finite wherever phi(u) is in (0, inf) even when phi itself over/underflows.
  virtual double log_generator(double u, double theta) const = 0;
  // log|phi'(u)|.
  virtual double log_abs_generator_derivative(double u, double theta) const = 0;
  // log|psi^{(k)}(s)| for k = 0..3, taking log s (so that s beyond the double range works).
  virtual double log_abs_inverse_derivative(int k, double log_s, double theta) const = 0;

  // ---- Margins and conditionals (sampling by conditional inversion) ----
  double cdf2(double u1, double u2, double theta) const;  // C(u1, u2, 1)
  // The 2-D margin's density; on the boundary of the square, the value at the nearest interior
  // double (the density may have no limit there).
  double density2(double u1, double u2, double theta) const;
  double conditional2(double u2, double u1, double theta) const;  // C(u2 | u1) = dC(u1,u2)/du1
  // C(u3 | u1, u2) = d^2 C(u1,u2,u3)/du1 du2 / c(u1,u2).
  double conditional3(double u3, double u1, double u2, double theta) const;
  // The u2 (u3) with conditional == p, by safeguarded Newton on a bracket; p in [0,1].
  double conditional2_inverse(double p, double u1, double theta) const;
  double conditional3_inverse(double p, double u1, double u2, double theta) const;

  // ---- Fast path for fitting over a grid ----
  // log c(u) = log_abs_inverse_third_derivative(s) + sum_i axis_term(u_i).log_abs_dpsi with
  // s = sum_i axis_term(u_i).psi. Precompute the axis terms once per parameter value; then one
  // bin costs two adds and one log/exp. Valid for u in (0, 1] where phi(u) is a finite, normal
  // double (it fails for Gumbel/Joe at large theta where phi overflows/underflows: use
  // log_density).
  AxisTerm axis_term(double u, double theta) const;
  double log_abs_inverse_third_derivative(double s, double theta) const;
  // The same with the parameter's constants computed once (prepare_fast_path(theta)): one
  // expm1/exp and one log per call for Frank, one log1p for Clayton, three calls for Gumbel and Joe
  // (falling back to the general path where that would lose accuracy).
  struct FastPath {
    double theta = 0;
    double k[4] = {0, 0, 0, 0};  // family-specific constants
  };
  virtual FastPath prepare_fast_path(double theta) const { return {theta, {0, 0, 0, 0}}; }
  double log_abs_inverse_third_derivative(double s, const FastPath& p) const {
    return prepared_third_derivative(s, p);
  }

 protected:
  // log|psi'''(s)| from prepared constants; the default ignores them.
  virtual double prepared_third_derivative(double s, const FastPath& p) const;
  // lim_{s->inf} psi^{(k)}(s + x) / psi^{(k)}(s) (the same for k = 1, 2 in every family here),
  // given log x: the conditionals at u1 = 0.
  virtual double tail_ratio(double log_x, double theta) const = 0;
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  static bool unit(double u) { return u >= 0.0 && u <= 1.0; }
};

// The one instance of each family. Values outside CopulaFamily give the independence copula
// (validate raw bytes with family_valid first).
const Copula& copula_for(CopulaFamily family);

}  // namespace cbrdf
