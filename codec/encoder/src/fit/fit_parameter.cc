// SPDX-License-Identifier: MIT
#include "fit/fit_parameter.h"

#include <algorithm>
#include <cmath>

#include "fit/fit_families.h"
#include "fit/loss.h"
#include "fit/solver_options.h"

namespace cbrdf::internal {
namespace {

// The least-squares problem of Eq. 17 over the measured bins, r_q = v_q / vbar - K c_q f_q with
// parameters (theta, K / vbar) (vbar: the mean measured value, so everything is of order 1), handed
// to Ceres in compressed form. With J (n x 2) the Jacobian of r and J^T J = R^T R (Cholesky), the
// three residuals rho = (R^{-T} J^T r, sqrt(|r|^2 - |R^{-T} J^T r|^2)) with Jacobian [R; 0] have
// the same cost |rho|^2 = |r|^2, the same J^T J and the same J^T r at every point, so
// Levenberg-Marquardt takes exactly the steps it would take on the n residuals. Each evaluation is
// then one streaming pass over the slice, and Ceres never stores an n x 2 Jacobian.
//
// Losses: kLinear r = v / vbar - m, kCosine the same times sqrt(cos theta_i cos theta_o), kLog
// r = log1p(v) - log1p(m vbar), with m = K' c f the model in units of vbar (v and vbar physical:
// the stored values times SliceData::unit).
class SliceCost final : public ceres::SizedCostFunction<3, 1, 1> {
 public:
  SliceCost(const SliceData& s, const Marginals& m, GridCopula& copula, double vbar, FitLoss loss)
      : s_(s),
        m_(m),
        copula_(copula),
        inv_vbar_(1.0 / vbar),
        physical_vbar_(vbar * s.unit),
        loss_(loss) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double theta = parameters[0][0], k = parameters[1][0];
    copula_.prepare(theta, m_.cdf_h, m_.cdf_d, m_.cdf_p);
    const bool want_jacobian = jacobians != nullptr;
    std::vector<double> c(std::size_t(s_.np)), dc(std::size_t(s_.np));
    // Sums of r^2, J^T J and J^T r, with J = (-K dc f, -c f).
    double rr = 0, jtt = 0, jtk = 0, jkk = 0, gt = 0, gk = 0;
    for (int i = 0; i < s_.nh; ++i) {
      for (int j = 0; j < s_.nd; ++j) {
        const std::size_t row = std::size_t(i) * std::size_t(s_.nd) + std::size_t(j);
        const std::uint32_t begin = s_.row_begin[row], end = s_.row_begin[row + 1];
        if (begin == end) continue;
        copula_.row(i, j, c.data(), want_jacobian ? dc.data() : nullptr);
        const double pdf_hd = m_.pdf_h[i] * m_.pdf_d[j];
        for (std::uint32_t q = begin; q < end; ++q) {
          const int l = s_.mk[q];
          const double f = pdf_hd * m_.pdf_p[l];
          const double model = k * c[l] * f;
          const auto [r, dr_dm] = loss_residual(loss_, s_, q, model, inv_vbar_, physical_vbar_);
          rr += r * r;
          if (!want_jacobian) continue;
          const double a = dr_dm * k * dc[l] * f, b = dr_dm * c[l] * f;
          jtt += a * a;
          jtk += a * b;
          jkk += b * b;
          gt += a * r;
          gk += b * r;
        }
      }
    }
    if (!want_jacobian) {
      residuals[0] = std::sqrt(rr);
      residuals[1] = residuals[2] = 0.0;
      return std::isfinite(rr);
    }
    // R = [[r11, r12], [0, r22]] with R^T R = J^T J; a vanishing direction gets R's row zeroed, and
    // its share of the cost moves to the third residual.
    const double r11 = std::sqrt(jtt);
    const double r12 = r11 > 0 ? jtk / r11 : 0.0;
    const double r22 = std::sqrt(std::max(0.0, jkk - r12 * r12));
    const double rho1 = r11 > 0 ? gt / r11 : 0.0;
    const double rho2 = r22 > 1e-300 ? (gk - r12 * rho1) / r22 : 0.0;
    residuals[0] = rho1;
    residuals[1] = rho2;
    residuals[2] = std::sqrt(std::max(0.0, rr - rho1 * rho1 - rho2 * rho2));
    if (jacobians[0]) {
      jacobians[0][0] = r11;
      jacobians[0][1] = 0.0;
      jacobians[0][2] = 0.0;
    }
    if (jacobians[1]) {
      jacobians[1][0] = r12;
      jacobians[1][1] = r22;
      jacobians[1][2] = 0.0;
    }
    return std::isfinite(rr) && std::isfinite(rho1) && std::isfinite(rho2);
  }

 private:
  const SliceData& s_;
  const Marginals& m_;
  GridCopula& copula_;
  double inv_vbar_, physical_vbar_;  // the log loss is in physical units
  FitLoss loss_;
};

double mean_measured(const SliceData& s) {
  double sum = 0;
  for (double v : s.mv) sum += v;
  return s.mv.empty() ? 0 : sum / double(s.mv.size());
}

// Calls f(q, p) for every measured bin q of the slice with p = c * pdf_h * pdf_d * pdf_p, the
// unscaled model at the copula's prepared parameter; rows without a measured bin are skipped.
template <typename F>
void for_each_measured(const SliceData& s, const Marginals& m, GridCopula& copula, F f) {
  std::vector<double> c(std::size_t(s.np));
  for (int i = 0; i < s.nh; ++i) {
    for (int j = 0; j < s.nd; ++j) {
      const std::size_t row = std::size_t(i) * std::size_t(s.nd) + std::size_t(j);
      const std::uint32_t begin = s.row_begin[row], end = s.row_begin[row + 1];
      if (begin == end) continue;
      copula.row(i, j, c.data(), nullptr);
      const double pdf_hd = m.pdf_h[i] * m.pdf_d[j];
      for (std::uint32_t q = begin; q < end; ++q) f(q, c[s.mk[q]] * pdf_hd * m.pdf_p[s.mk[q]]);
    }
  }
}

}  // namespace

ParameterFit evaluate_parameter(const SliceData& s, const Marginals& m, GridCopula& copula,
                                double theta, FitLoss loss) {
  ParameterFit r;
  r.theta = theta;
  const double vbar = mean_measured(s);
  if (s.mv.empty() || vbar <= 0) return r;
  copula.prepare(theta, m.cdf_h, m.cdf_d, m.cdf_p);
  double vp = 0, pp = 0, vv = 0;
  for_each_measured(s, m, copula, [&](std::uint32_t q, double p) {
    const double v = s.mv[q] / vbar;
    const double w = loss == FitLoss::kCosine ? s.mw[q] : 1.0;
    vp += w * v * p;
    pp += w * p * p;
    vv += w * v * v;
  });
  const double k = pp > 0 ? vp / pp : 0;
  r.scale = k * vbar;
  r.objective = std::max(0.0, vv - 2 * k * vp + k * k * pp) / double(s.measured_count());
  if (loss == FitLoss::kLog) {
    // A second pass: the log loss has no closed form in K.
    double sum = 0;
    for_each_measured(s, m, copula, [&](std::uint32_t q, double p) {
      const double d = std::log1p(s.mv[q] * s.unit) - std::log1p(r.scale * s.unit * p);
      sum += d * d;
    });
    r.objective = sum / double(s.measured_count());
  }
  return r;
}

ParameterFit fit_parameter(const SliceData& s, const Marginals& m, GridCopula& copula,
                           FitLoss loss) {
  const double lo = copula.search_lo(), hi = copula.search_hi();
  ParameterFit best = evaluate_parameter(s, m, copula, copula.independence(), loss);
  best.objective_independence = best.objective;
  if (lo == hi || s.mv.empty() || best.scale <= 0) return best;
  // Coarse scan for a start (the family's fitter row): the objective can have shallow local
  // minima far from independence.
  for (double theta : fit_family_row(copula.family())->scan) {
    if (cancel_requested()) return best;  // the encode returns kCancelled
    if (theta < lo || theta > hi) continue;
    ParameterFit r = evaluate_parameter(s, m, copula, theta, loss);
    r.objective_independence = best.objective_independence;
    if (r.objective < best.objective) best = r;
  }
  const double vbar = mean_measured(s);
  double theta = best.theta, k = best.scale / vbar;
  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  problem.AddResidualBlock(new SliceCost(s, m, copula, vbar, loss), nullptr, &theta, &k);
  problem.SetParameterLowerBound(&theta, 0, lo);
  problem.SetParameterUpperBound(&theta, 0, hi);
  const ceres::Solver::Options options = small_problem_options();
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  // Ceres's cost is half the sum of squares of the (compressed) residuals: the objective at its
  // solution, with K jointly optimal, without another pass over the slice.
  ParameterFit r;
  r.theta = std::clamp(theta, lo, hi);
  r.scale = k * vbar;
  r.objective = 2.0 * summary.final_cost / double(s.measured_count());
  r.objective_independence = best.objective_independence;
  r.iterations = int(summary.iterations.size());
  // The solver only ever improves on its start; keep the start if rounding says otherwise.
  if (!(r.objective <= best.objective)) {
    best.iterations = r.iterations;
    return best;
  }
  return r;
}

}  // namespace cbrdf::internal
