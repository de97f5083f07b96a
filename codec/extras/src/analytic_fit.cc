// SPDX-License-Identifier: MIT
// fit_analytic(): a scan for a start, then Ceres on every parameter (analytic_fit.h).
#include "cbrdf/analytic_fit.h"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "analytic/lobes.h"
#include "cbrdf/coords.h"

namespace cbrdf {
namespace {

using internal::PairGeometry;

struct FitBin {
  PairGeometry g;
  std::array<double, 3> m{};  // measured, physical
  double w = 0.0;             // the loss's weight per channel residual (sums to 1 over all)
};

std::uint64_t splitmix64(std::uint64_t* state) {
  std::uint64_t z = (*state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// The bin's Rusinkiewicz measure (metrics.h): the same weight brdf_metrics' cos_rmse uses.
double bin_measure(int h, int d) {
  const double s0 = std::sin(theta_d_of(d)), s1 = std::sin(theta_d_of(d + 1));
  return (std::cos(theta_h_of(h)) - std::cos(theta_h_of(h + 1))) * (s1 * s1 - s0 * s0) / 2;
}

// Eligible bins (measured everywhere, both directions within max_angle), then a partial
// Fisher-Yates draw with a fixed generator so that a seed always picks the same bins.
std::vector<FitBin> draw_bins(const BrdfTable& table, const AnalyticFitSettings& st) {
  const double min_cos = std::cos(st.max_angle_deg * std::numbers::pi / 180.0) - 1e-12;
  std::vector<std::uint32_t> eligible;
  for (std::size_t idx = 0; idx < kBinsPerChannel; ++idx) {
    if (!table.measured(0, idx) || !table.measured(1, idx) || !table.measured(2, idx)) continue;
    const BinIndex b = merl_bin(idx);
    Vec3 wi, wo;
    from_half_diff({theta_h_of(b.theta_h), 0.0, theta_d_of(b.theta_d), phi_d_of(b.phi_d)}, &wi,
                   &wo);
    if (wi.z > 0.0 && wo.z > 0.0 && wi.z >= min_cos && wo.z >= min_cos) {
      eligible.push_back(std::uint32_t(idx));
    }
  }
  const std::size_t n = eligible.size();
  std::size_t k = n;
  if (st.sample_bins > 0 && std::size_t(st.sample_bins) < n) {
    k = std::size_t(st.sample_bins);
    std::uint64_t state = st.seed;
    for (std::size_t i = 0; i < k; ++i) {
      const std::size_t j = i + std::size_t(splitmix64(&state) % (n - i));
      std::swap(eligible[i], eligible[j]);
    }
    eligible.resize(k);
    std::sort(eligible.begin(), eligible.end());
  }
  std::vector<FitBin> bins;
  bins.reserve(k);
  double sum_w = 0.0;
  for (std::uint32_t idx : eligible) {
    const BinIndex b = merl_bin(idx);
    Vec3 wi, wo;
    from_half_diff({theta_h_of(b.theta_h), 0.0, theta_d_of(b.theta_d), phi_d_of(b.phi_d)}, &wi,
                   &wo);
    FitBin fb;
    if (!internal::pair_geometry(wi, wo, &fb.g)) continue;
    for (int c = 0; c < kChannels; ++c) fb.m[std::size_t(c)] = table.physical(c, idx);
    fb.w = st.loss == AnalyticLoss::kCosineWeighted
               ? fb.g.cos_i * fb.g.cos_o * bin_measure(b.theta_h, b.theta_d)
               : 1.0;
    sum_w += fb.w;
    bins.push_back(fb);
  }
  // Normalized over bins and the three channels, so a loss is a mean squared error.
  for (FitBin& fb : bins) fb.w = sum_w > 0 ? fb.w / (3.0 * sum_w) : 0.0;
  return bins;
}

double residual(AnalyticLoss loss, double f, double m) {
  return loss == AnalyticLoss::kLog ? std::log1p(std::max(f, 0.0)) - std::log1p(m) : f - m;
}

double loss_of(const std::vector<Lobe>& lobes, const std::vector<FitBin>& bins, AnalyticLoss loss) {
  double sum = 0.0;
  for (const FitBin& b : bins) {
    double rgb[3] = {0, 0, 0};
    for (const Lobe& l : lobes) internal::add_lobe(l, b.g, rgb);
    for (int c = 0; c < 3; ++c) {
      const double r = residual(loss, rgb[c], b.m[std::size_t(c)]);
      sum += b.w * r * r;
    }
  }
  return sum;
}

// Sets the colours of lobes [0, count) (the others are left out) to the non-negative weighted
// least-squares optimum per channel. Each lobe is affine in its colour x: value = x A + B, with A
// and B the same for every channel, so the normal equations are shared and only the right-hand
// side differs; the non-negative optimum is the best feasible unconstrained optimum over subsets.
void fit_colours(std::vector<Lobe>* lobes, std::size_t count, const std::vector<FitBin>& bins) {
  const int k = int(count);
  Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(k, k);
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(k, 3);
  std::vector<double> a(count);
  for (const FitBin& b : bins) {
    double offset = 0.0;
    for (std::size_t l = 0; l < count; ++l) {
      Lobe unit = (*lobes)[l], zero = (*lobes)[l];
      unit.rgb = {1, 1, 1};
      zero.rgb = {0, 0, 0};
      double v1[3] = {0, 0, 0}, v0[3] = {0, 0, 0};
      internal::add_lobe(unit, b.g, v1);
      internal::add_lobe(zero, b.g, v0);
      a[l] = v1[0] - v0[0];
      offset += v0[0];
    }
    for (int i = 0; i < k; ++i) {
      for (int j = 0; j < k; ++j) gram(i, j) += b.w * a[std::size_t(i)] * a[std::size_t(j)];
      for (int c = 0; c < 3; ++c) {
        rhs(i, c) += b.w * a[std::size_t(i)] * (b.m[std::size_t(c)] - offset);
      }
    }
  }
  for (int c = 0; c < 3; ++c) {
    Eigen::VectorXd best = Eigen::VectorXd::Zero(k);
    double best_gain = 0.0;  // reduction of the squared error from all-zero colours
    for (unsigned subset = 1; subset < (1u << k); ++subset) {
      std::vector<int> idx;
      for (int i = 0; i < k; ++i) {
        if (subset & (1u << i)) idx.push_back(i);
      }
      const int s = int(idx.size());
      Eigen::MatrixXd g(s, s);
      Eigen::VectorXd h(s);
      for (int i = 0; i < s; ++i) {
        h(i) = rhs(idx[std::size_t(i)], c);
        for (int j = 0; j < s; ++j) g(i, j) = gram(idx[std::size_t(i)], idx[std::size_t(j)]);
      }
      const Eigen::VectorXd x = g.ldlt().solve(h);
      if (!x.allFinite() || (x.array() < 0.0).any()) continue;
      const double gain = x.dot(h);  // at the optimum, error = y.y - x.h
      if (gain > best_gain) {
        best_gain = gain;
        best.setZero();
        for (int i = 0; i < s; ++i) best(idx[std::size_t(i)]) = x(i);
      }
    }
    for (std::size_t l = 0; l < count; ++l) (*lobes)[l].rgb[std::size_t(c)] = best(int(l));
  }
}

std::vector<double> shape_grid(LobeKind kind) {
  constexpr int kSteps = 24;
  // Microfacet roughness from near-mirror to very rough; Ashikhmin-Shirley exponents likewise.
  const double lo = kind == LobeKind::kAshikhminShirley ? 1.0 : 0.005;
  const double hi = kind == LobeKind::kAshikhminShirley ? 1e5 : 1.0;
  std::vector<double> grid;
  for (int i = 0; i < kSteps; ++i) grid.push_back(lo * std::pow(hi / lo, double(i) / (kSteps - 1)));
  return grid;
}

// Lobes in order: each specular lobe's shape scanned with the lobes before it kept, colours of
// all of them re-fitted per candidate; Lambertian lobes join with their colour only.
std::vector<Lobe> scan_start(const std::vector<LobeKind>& kinds, const std::vector<FitBin>& bins,
                             AnalyticLoss loss) {
  std::vector<Lobe> lobes;
  for (LobeKind kind : kinds) lobes.push_back(Lobe{kind, {0, 0, 0}, 0.0});
  for (std::size_t l = 0; l < lobes.size(); ++l) {
    if (lobes[l].kind == LobeKind::kLambertian) {
      fit_colours(&lobes, l + 1, bins);
      continue;
    }
    std::vector<Lobe> best;
    double best_loss = std::numeric_limits<double>::infinity();
    for (double shape : shape_grid(lobes[l].kind)) {
      std::vector<Lobe> trial = lobes;
      trial[l].shape = shape;
      fit_colours(&trial, l + 1, bins);
      const std::vector<Lobe> used(trial.begin(), trial.begin() + std::ptrdiff_t(l + 1));
      const double value = loss_of(used, bins, loss);
      if (value < best_loss) {
        best_loss = value;
        best = trial;
      }
    }
    lobes = best;
  }
  return lobes;
}

// One block of bins' residuals, sqrt(w) * (f - m) (or of the logs), for every channel.
class ChunkResidual {
 public:
  ChunkResidual(const std::vector<Lobe>* shape, const FitBin* bins, std::size_t count,
                AnalyticLoss loss)
      : lobes_(*shape), bins_(bins), count_(count), loss_(loss) {}

  bool operator()(double const* const* params, double* residuals) const {
    std::vector<Lobe> lobes = lobes_;
    for (std::size_t l = 0; l < lobes.size(); ++l) {
      for (int c = 0; c < 3; ++c) lobes[l].rgb[std::size_t(c)] = params[l][c];
      if (lobes[l].kind != LobeKind::kLambertian) lobes[l].shape = params[l][3];
    }
    for (std::size_t i = 0; i < count_; ++i) {
      const FitBin& b = bins_[i];
      double rgb[3] = {0, 0, 0};
      for (const Lobe& l : lobes) internal::add_lobe(l, b.g, rgb);
      const double sw = std::sqrt(b.w);
      for (int c = 0; c < 3; ++c) {
        const double r = sw * residual(loss_, rgb[c], b.m[std::size_t(c)]);
        if (!std::isfinite(r)) return false;
        residuals[3 * i + std::size_t(c)] = r;
      }
    }
    return true;
  }

 private:
  std::vector<Lobe> lobes_;
  const FitBin* bins_;
  std::size_t count_;
  AnalyticLoss loss_;
};

Status check_settings(const AnalyticFitSettings& st) {
  if (st.lobes.empty() || st.lobes.size() > std::size_t(kMaxFitLobes)) {
    return error(ErrorCode::kInvalidArgument, "analytic fit: give 1 to " +
                                                  std::to_string(kMaxFitLobes) + " lobes, not " +
                                                  std::to_string(st.lobes.size()));
  }
  for (LobeKind kind : st.lobes) {
    if (std::uint8_t(kind) > std::uint8_t(LobeKind::kAshikhminShirley)) {
      return error(ErrorCode::kInvalidArgument,
                   "analytic fit: unknown lobe kind " + std::to_string(int(kind)));
    }
  }
  if (st.sample_bins < 0) {
    return error(ErrorCode::kInvalidArgument,
                 "analytic fit: sample_bins must be >= 0, not " + std::to_string(st.sample_bins));
  }
  if (!(st.max_angle_deg > 0.0 && st.max_angle_deg <= 90.0)) {
    return error(
        ErrorCode::kInvalidArgument,
        "analytic fit: max_angle_deg must be in (0, 90], not " + std::to_string(st.max_angle_deg));
  }
  if (!(st.function_tolerance > 0.0 && st.function_tolerance < 1.0)) {
    return error(ErrorCode::kInvalidArgument,
                 "analytic fit: function_tolerance must be in (0, 1), not " +
                     std::to_string(st.function_tolerance));
  }
  if (st.max_iterations < 1 || st.threads < 1) {
    return error(ErrorCode::kInvalidArgument,
                 "analytic fit: max_iterations and threads must be at least 1");
  }
  return ok_status();
}

}  // namespace

Expected<AnalyticBrdf> fit_analytic(const BrdfTable& table, const AnalyticFitSettings& st,
                                    AnalyticFitReport* report) {
  CBRDF_RETURN_IF_ERROR(check_settings(st));
  const std::vector<FitBin> bins = draw_bins(table, st);
  if (bins.empty()) {
    return error(ErrorCode::kInvalidArgument,
                 "analytic fit: no bin is measured in every channel with theta_i and theta_o "
                 "within " +
                     std::to_string(st.max_angle_deg) + " degrees");
  }
  const std::vector<Lobe> start = scan_start(st.lobes, bins, st.loss);
  const double start_loss = loss_of(start, bins, st.loss);

  std::vector<std::array<double, 4>> params(start.size());
  for (std::size_t l = 0; l < start.size(); ++l) {
    params[l] = {start[l].rgb[0], start[l].rgb[1], start[l].rgb[2], start[l].shape};
  }
  ceres::Problem problem;
  constexpr std::size_t kChunk = 1024;
  for (std::size_t first = 0; first < bins.size(); first += kChunk) {
    const std::size_t count = std::min(kChunk, bins.size() - first);
    auto* cost = new ceres::DynamicNumericDiffCostFunction<ChunkResidual>(
        new ChunkResidual(&start, bins.data() + first, count, st.loss));
    std::vector<double*> blocks;
    for (std::size_t l = 0; l < start.size(); ++l) {
      cost->AddParameterBlock(start[l].num_params());
      blocks.push_back(params[l].data());
    }
    cost->SetNumResiduals(int(3 * count));
    problem.AddResidualBlock(cost, nullptr, blocks);
  }
  for (std::size_t l = 0; l < start.size(); ++l) {
    double* p = params[l].data();
    for (int c = 0; c < 3; ++c) problem.SetParameterLowerBound(p, c, 0.0);
    if (start[l].kind == LobeKind::kAshikhminShirley) {
      problem.SetParameterLowerBound(p, 3, 0.0);
      problem.SetParameterUpperBound(p, 3, kMaxExponent);
    } else if (start[l].kind != LobeKind::kLambertian) {
      problem.SetParameterLowerBound(p, 3, kMinAlpha);
      problem.SetParameterUpperBound(p, 3, kMaxAlpha);
    }
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;  // at most 16 parameters
  options.logging_type = ceres::SILENT;
  options.max_num_iterations = st.max_iterations;
  options.function_tolerance = st.function_tolerance;
  options.gradient_tolerance = 1e-14;
  options.parameter_tolerance = 1e-10;
  options.num_threads = st.threads;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);

  std::vector<Lobe> fitted = start;
  for (std::size_t l = 0; l < fitted.size(); ++l) {
    for (int c = 0; c < 3; ++c) fitted[l].rgb[std::size_t(c)] = params[l][std::size_t(c)];
    if (fitted[l].kind != LobeKind::kLambertian) fitted[l].shape = params[l][3];
  }
  double final_loss = loss_of(fitted, bins, st.loss);
  // The solver only accepts improving steps; keep the start should rounding say otherwise.
  if (!(final_loss <= start_loss) || !AnalyticBrdf{fitted}.validate().ok()) {
    fitted = start;
    final_loss = start_loss;
  }
  if (report) {
    report->bins = int(bins.size());
    report->start_cost = start_loss;
    report->final_cost = final_loss;
    report->iterations = int(summary.iterations.size());
  }
  return AnalyticBrdf{fitted};
}

}  // namespace cbrdf
