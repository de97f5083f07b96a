// SPDX-License-Identifier: MIT
// GridCopula for the families without a grid of their own (registry.h), through the
// Archimedean fast path of copula.h: log c = log|psi'''(s)| + sum_i log|phi'(u_i)|, s = sum_i
// phi(u_i). Per-axis terms are prepared once per parameter, so a bin costs two adds, one log/exp
// and the family's third derivative. Where the fast path is not finite (phi over- or underflows at
// large parameters) the bin falls back to the general log_density. The derivative in the parameter
// is a one-sided difference with a second prepared grid (the fitter only needs it to steer: Ceres's
// cost, and so its acceptance of steps, is exact).
//
// Work per bin is bounded whatever the parameter (spec/container.md, "Resource bounds"): where the
// sum s of the phi is not a normal double (phi underflows at large Gumbel or Joe parameters and at
// very negative Frank ones), log s comes from the prepared log phi by a log-sum-exp, so that the
// bin costs one log and a few exp more than the fast path, instead of the general log_density
// (about 15 transcendental calls, many on subnormal or overflowing arguments, 10x the fast path).
#include <algorithm>
#include <cmath>
#include <limits>

#include "copula/copula.h"
#include "copula/registry.h"
#include "density/grid_copula.h"

namespace cbrdf::internal {
namespace {

struct AxisTerms {
  std::vector<double> psi, log_psi, log_dpsi, u;
};

// log(e^a + e^b + e^c), skipping the exp of terms that underflow anyway (an exp that underflows
// goes through libm's slow error path).
double log_sum_exp3(double a, double b, double c) {
  const double m = std::max({a, b, c});
  if (!(m > -std::numeric_limits<double>::infinity()) ||
      m == std::numeric_limits<double>::infinity()) {
    return m;
  }
  double sum = 0;
  for (double x : {a, b, c}) {
    if (x - m > -746.0) sum += std::exp(x - m);
  }
  return m + std::log(sum);
}

// The family's prepared third derivative (Copula::prepared_third_derivative) for a positive, finite
// s, inline: the same operations in the same order (so the same bits) with the parameter's
// constants formed once, instead of two virtual calls, a domain check and three divisions per bin.
// NaN: not handled here (take the family's own).
struct InlineThird {
  CopulaFamily family = CopulaFamily::kIndependence;
  double theta = 0, k0 = 0, k1 = 0, a = 0, b = 0, c = 0;

  void prepare(CopulaFamily f, double t, const Copula::FastPath& p) {
    family = f;
    theta = t;
    k0 = p.k[0];
    k1 = p.k[1];
    const double alpha = 1.0 / t;
    const double one_m_alpha = (t - 1.0) / t;
    const double two_m_alpha = (2.0 * t - 1.0) / t;
    if (f == CopulaFamily::kGumbel) {  // q3 = a y^2 + b y + c (gumbel.cc)
      a = alpha * alpha;
      b = 3.0 * alpha * one_m_alpha;
      c = one_m_alpha * two_m_alpha;
    } else if (f == CopulaFamily::kJoe) {  // b3 = c + b z + a z^2 (joe.cc)
      a = alpha * alpha;
      b = (2.0 * alpha - 1.0) * one_m_alpha;
      c = one_m_alpha * two_m_alpha;
    }
  }
  double operator()(double s) const {
    switch (family) {
      case CopulaFamily::kGumbel: {
        const double log_s = std::log(s);
        const double log_y = k0 * log_s;
        const double y = std::exp(log_y);
        return -y - 3.0 * log_s + k1 + log_y + std::log(a * y * y + b * y + c);
      }
      case CopulaFamily::kClayton: {
        const double y = theta * s;
        if (!std::isfinite(y)) break;
        const double l = std::log1p(y);
        const double l_over_theta = y < 1e-200 ? s : l / theta;
        return k0 - l_over_theta - 3.0 * l;
      }
      case CopulaFamily::kJoe: {
        const double z = -std::expm1(-s);
        if (theta == 1.0 || !(z >= 1e-300)) break;
        return k1 - s + (k0 - 3.0) * std::log(z) + std::log(c + b * z + a * z * z);
      }
      default:
        break;
    }
    return std::numeric_limits<double>::quiet_NaN();
  }
  bool handles(double s) const {
    return (family == CopulaFamily::kGumbel || family == CopulaFamily::kClayton ||
            family == CopulaFamily::kJoe) &&
           s > 0.0 && s < std::numeric_limits<double>::infinity();
  }
};

class PreparedGrid {
 public:
  void prepare(const Copula& c, double theta, const std::vector<double>* u[3]) {
    copula_ = &c;
    theta_ = theta;
    path_ = c.prepare_fast_path(theta);
    inline_.prepare(c.family(), theta, path_);
    for (int a = 0; a < 3; ++a) {
      AxisTerms& t = axes_[a];
      t.u = *u[a];
      t.psi.resize(t.u.size());
      t.log_psi.resize(t.u.size());
      t.log_dpsi.resize(t.u.size());
      for (std::size_t i = 0; i < t.u.size(); ++i) {
        // axis_term(u).psi is exactly exp(log_generator(u)).
        t.log_psi[i] = c.log_generator(t.u[i], theta);
        t.psi[i] = std::exp(t.log_psi[i]);
        t.log_dpsi[i] = c.log_abs_generator_derivative(t.u[i], theta);
      }
    }
  }
  double density(int i, int j, int k) const {
    ++grid_work_counters().densities;
    const double s = axes_[0].psi[i] + axes_[1].psi[j] + axes_[2].psi[k];
    const double l = axes_[0].log_dpsi[i] + axes_[1].log_dpsi[j] + axes_[2].log_dpsi[k];
    double log_c;
    if (std::isnormal(s) && inline_.handles(s)) {
      log_c = inline_(s);
      if (log_c != log_c) log_c = copula_->log_abs_inverse_third_derivative(s, path_);
      log_c += l;
    } else if (std::isnormal(s) || s == std::numeric_limits<double>::infinity()) {
      log_c = copula_->log_abs_inverse_third_derivative(s, path_) + l;
    } else {
      ++grid_work_counters().log_sum_paths;
      const double log_s =
          log_sum_exp3(axes_[0].log_psi[i], axes_[1].log_psi[j], axes_[2].log_psi[k]);
      log_c = copula_->log_abs_inverse_derivative(3, log_s, theta_) + l;
    }
    if (!std::isfinite(log_c) && !(log_c == -std::numeric_limits<double>::infinity())) {
      ++grid_work_counters().general_paths;
      log_c = copula_->log_density(axes_[0].u[i], axes_[1].u[j], axes_[2].u[k], theta_);
    }
    const double c = std::exp(log_c);
    return std::isfinite(c) ? c : 0.0;
  }

 private:
  const Copula* copula_ = nullptr;
  double theta_ = 0;
  Copula::FastPath path_;
  InlineThird inline_;
  AxisTerms axes_[3];
};

class ArchimedeanGrid final : public GridCopula {
 public:
  explicit ArchimedeanGrid(const CopulaFamilyRow& row)
      : GridCopula(row), copula_(row.copula()), hi_(row.search_hi) {}

  void prepare(double theta, const std::vector<double>& u1, const std::vector<double>& u2,
               const std::vector<double>& u3) override {
    const std::vector<double>* u[3] = {&u1, &u2, &u3};
    n3_ = int(u3.size());
    grid_.prepare(copula_, theta, u);
    // Forward inside the domain, backward at its upper end.
    const double step = 1e-6 * std::max(1.0, std::abs(theta));
    other_theta_ = theta + step <= hi_ ? theta + step : theta - step;
    other_.prepare(copula_, other_theta_, u);
    span_ = other_theta_ - theta;
    derivatives_ = true;
  }
  void prepare_density(double theta, const std::vector<double>& u1, const std::vector<double>& u2,
                       const std::vector<double>& u3) override {
    const std::vector<double>* u[3] = {&u1, &u2, &u3};
    n3_ = int(u3.size());
    grid_.prepare(copula_, theta, u);
    derivatives_ = false;
  }
  double density(int i, int j, int k) const override { return grid_.density(i, j, k); }
  double density_and_derivative(int i, int j, int k, double* d) const override {
    const double c = grid_.density(i, j, k);
    *d = derivatives_ ? (other_.density(i, j, k) - c) / span_
                      : std::numeric_limits<double>::quiet_NaN();
    return c;
  }
  void row(int i, int j, double* c, double* dc) const override {
    for (int k = 0; k < n3_; ++k) {
      c[k] = grid_.density(i, j, k);
      if (dc)
        dc[k] = derivatives_ ? (other_.density(i, j, k) - c[k]) / span_
                             : std::numeric_limits<double>::quiet_NaN();
    }
  }

 private:
  const Copula& copula_;
  double hi_;
  int n3_ = 0;
  double other_theta_ = 0, span_ = 1;
  bool derivatives_ = false;  // other_ prepared (prepare, not prepare_density)
  PreparedGrid grid_, other_;
};

}  // namespace

GridWorkCounters& grid_work_counters() {
  thread_local GridWorkCounters counters;
  return counters;
}

std::unique_ptr<GridCopula> make_archimedean_grid(CopulaFamily family) {
  const CopulaFamilyRow* row = family_row(family);
  if (!row || !row->has_parameter()) return nullptr;
  return std::make_unique<ArchimedeanGrid>(*row);
}

}  // namespace cbrdf::internal
