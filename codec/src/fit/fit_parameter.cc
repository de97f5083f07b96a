#include "fit/fit_parameter.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace cbrdf::fit {
namespace {

// Residuals over the measured bins: (v - K c f1 f2 f3) / vbar, for parameters (theta, K / vbar),
// where vbar is the mean measured value, so residuals and parameters are of order 1.
class SliceCost final : public ceres::CostFunction {
 public:
  SliceCost(const SliceData& s, const Marginals& m, GridCopula& copula, double vbar)
      : s_(s), m_(m), copula_(copula), inv_vbar_(1.0 / vbar) {
    set_num_residuals(int(s.measured_count()));
    mutable_parameter_block_sizes()->push_back(1);
    mutable_parameter_block_sizes()->push_back(1);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double theta = parameters[0][0], k = parameters[1][0];
    copula_.prepare(theta, m_.u1, m_.u2, m_.u3);
    const bool want_theta = jacobians && jacobians[0];
    const bool want_k = jacobians && jacobians[1];
    std::vector<double> c(std::size_t(s_.np)), dc(std::size_t(s_.np));
    for (int i = 0; i < s_.nh; ++i) {
      for (int j = 0; j < s_.nd; ++j) {
        const std::size_t r = std::size_t(i) * std::size_t(s_.nd) + std::size_t(j);
        const std::uint32_t begin = s_.row_begin[r], end = s_.row_begin[r + 1];
        if (begin == end) continue;
        copula_.row(i, j, c.data(), want_theta ? dc.data() : nullptr);
        const double f12 = m_.f1[i] * m_.f2[j];
        for (std::uint32_t q = begin; q < end; ++q) {
          const int l = s_.mk[q];
          const double f = f12 * m_.f3[l];
          residuals[q] = s_.mv[q] * inv_vbar_ - k * c[l] * f;
          if (want_theta) jacobians[0][q] = -k * dc[l] * f;
          if (want_k) jacobians[1][q] = -c[l] * f;
        }
      }
    }
    return true;
  }

 private:
  const SliceData& s_;
  const Marginals& m_;
  GridCopula& copula_;
  double inv_vbar_;
};

double mean_measured(const SliceData& s) {
  double sum = 0;
  for (double v : s.mv) sum += v;
  return s.mv.empty() ? 0 : sum / double(s.mv.size());
}

}  // namespace

ParameterFit evaluate_parameter(const SliceData& s, const Marginals& m, GridCopula& copula,
                                double theta) {
  ParameterFit r;
  r.theta = theta;
  const double vbar = mean_measured(s);
  if (s.mv.empty() || vbar <= 0) return r;
  copula.prepare(theta, m.u1, m.u2, m.u3);
  double vp = 0, pp = 0, vv = 0;
  std::vector<double> c(std::size_t(s.np));
  for (int i = 0; i < s.nh; ++i) {
    for (int j = 0; j < s.nd; ++j) {
      const std::size_t row = std::size_t(i) * std::size_t(s.nd) + std::size_t(j);
      const std::uint32_t begin = s.row_begin[row], end = s.row_begin[row + 1];
      if (begin == end) continue;
      copula.row(i, j, c.data(), nullptr);
      const double f12 = m.f1[i] * m.f2[j];
      for (std::uint32_t q = begin; q < end; ++q) {
        const double p = c[s.mk[q]] * f12 * m.f3[s.mk[q]];
        const double v = s.mv[q] / vbar;
        vp += v * p;
        pp += p * p;
        vv += v * v;
      }
    }
  }
  const double k = pp > 0 ? vp / pp : 0;
  r.scale = k * vbar;
  r.objective = std::max(0.0, vv - 2 * k * vp + k * k * pp) / double(s.measured_count());
  return r;
}

ParameterFit fit_parameter(const SliceData& s, const Marginals& m, GridCopula& copula) {
  const double lo = copula.fit_lo(), hi = copula.fit_hi();
  ParameterFit best = evaluate_parameter(s, m, copula, copula.independence());
  if (lo == hi || s.mv.empty() || best.scale <= 0) return best;
  // Coarse scan for a start: the objective can have shallow local minima far from independence.
  // Frank (independence inside the range) scans both sides; the others start at independence.
  const double ind = copula.independence();
  const std::vector<double> scan = lo < ind && ind < hi
                                       ? std::vector<double>{-30.0, -5.0, -1.0, 0.4}
                                       : std::vector<double>{ind + 0.1, ind + 0.5, ind + 2, ind + 8};
  for (double theta : scan) {
    if (theta < lo || theta > hi) continue;
    const ParameterFit r = evaluate_parameter(s, m, copula, theta);
    if (r.objective < best.objective) best = r;
  }
  const double vbar = mean_measured(s);
  double theta = best.theta, k = best.scale / vbar;
  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  problem.AddResidualBlock(new SliceCost(s, m, copula, vbar), nullptr, &theta, &k);
  problem.SetParameterLowerBound(&theta, 0, lo);
  problem.SetParameterUpperBound(&theta, 0, hi);
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;  // 2 parameters: J^T J is 2x2
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  options.max_num_iterations = 50;
  options.function_tolerance = 1e-10;
  options.gradient_tolerance = 1e-12;
  options.parameter_tolerance = 1e-10;
  options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  if (std::getenv("CBRDF_CERES_REPORT")) std::fprintf(stderr, "%s\n", summary.FullReport().c_str());
  ParameterFit r = evaluate_parameter(s, m, copula, std::clamp(theta, lo, hi));
  r.iterations = int(summary.iterations.size());
  // The solver only ever improves on its start; keep the start if rounding says otherwise.
  if (!(r.objective <= best.objective)) {
    best.iterations = r.iterations;
    return best;
  }
  return r;
}

}  // namespace cbrdf::fit
