// SPDX-License-Identifier: MIT
// BRDF-space error metrics (metrics.h documents the exact definitions).
#include "metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>

#include "parallel_for.h"

namespace cbrdf {
namespace {

// cos(theta_i) cos(theta_o) at the bin's grid pair times the bin's Rusinkiewicz measure; computed
// once (1.46 M bins) because every report asks for it.
const std::vector<double>& cosine_bin_weights() {
  static std::once_flag once;
  static std::vector<double> weights;
  std::call_once(once, [] {
    weights.assign(kBinsPerChannel, 0.0);
    internal::parallel_rows(kThetaHBins, 0, [](int h_begin, int h_end) {
      for (int h = h_begin; h < h_end; ++h) {
        const double h_measure = std::cos(theta_h_of(h)) - std::cos(theta_h_of(h + 1));
        for (int d = 0; d < kThetaDBins; ++d) {
          const double s0 = std::sin(theta_d_of(d)), s1 = std::sin(theta_d_of(d + 1));
          const double measure = h_measure * (s1 * s1 - s0 * s0) / 2;
          for (int p = 0; p < kPhiDBins; ++p) {
            Vec3 wi, wo;
            from_half_diff({theta_h_of(h), 0.0, theta_d_of(d), phi_d_of(p)}, &wi, &wo);
            const double cosines = std::max(wi.z, 0.0) * std::max(wo.z, 0.0);
            weights[merl_index(h, d, p)] = cosines * measure;
          }
        }
      }
    });
  });
  return weights;
}

// Per-channel sums over one theta_h row, kept apart so the final sum has a fixed order.
struct RowSums {
  std::array<double, 3> sq_err{}, sq_ref{}, log_sq_err{}, w_sq_err{}, w{};
  std::array<std::size_t, 3> n{};
};

// test_at(theta_h, theta_d, phi_d, index, rgb) gives the test's physical RGB at a reference bin.
template <typename TestAt>
BrdfMetrics accumulate(const BrdfTable& reference, int threads, const TestAt& test_at) {
  const std::vector<double>& weights = cosine_bin_weights();
  std::vector<RowSums> rows(kThetaHBins);
  internal::parallel_rows(kThetaHBins, threads, [&](int h_begin, int h_end) {
    for (int h = h_begin; h < h_end; ++h) {
      RowSums& s = rows[std::size_t(h)];
      for (int d = 0; d < kThetaDBins; ++d) {
        for (int p = 0; p < kPhiDBins; ++p) {
          const std::size_t idx = merl_index(h, d, p);
          bool any = false;
          for (int c = 0; c < kChannels; ++c) any = any || reference.measured(c, idx);
          if (!any) continue;
          double t[3];
          test_at(h, d, p, idx, t);
          for (int c = 0; c < kChannels; ++c) {
            if (!reference.measured(c, idx)) continue;
            const std::size_t ci = std::size_t(c);
            const double r = reference.physical(c, idx);
            const double e = t[c] - r;
            const double le = std::log1p(std::max(t[c], 0.0)) - std::log1p(r);
            s.sq_err[ci] += e * e;
            s.sq_ref[ci] += r * r;
            s.log_sq_err[ci] += le * le;
            s.w_sq_err[ci] += weights[idx] * e * e;
            s.w[ci] += weights[idx];
            ++s.n[ci];
          }
        }
      }
    }
  });
  RowSums total;
  for (const RowSums& s : rows) {
    for (std::size_t c = 0; c < 3; ++c) {
      total.sq_err[c] += s.sq_err[c];
      total.sq_ref[c] += s.sq_ref[c];
      total.log_sq_err[c] += s.log_sq_err[c];
      total.w_sq_err[c] += s.w_sq_err[c];
      total.w[c] += s.w[c];
      total.n[c] += s.n[c];
    }
  }
  BrdfMetrics m;
  for (std::size_t c = 0; c < 3; ++c) {
    if (total.sq_ref[c] > 0) {
      m.rel_rmse[c] = std::sqrt(total.sq_err[c] / total.sq_ref[c]);
    } else {
      m.rel_rmse[c] = total.sq_err[c] > 0 ? std::numeric_limits<double>::infinity() : 0.0;
    }
    m.log_rmse[c] = total.n[c] > 0 ? std::sqrt(total.log_sq_err[c] / double(total.n[c])) : 0.0;
    m.cos_rmse[c] = total.w[c] > 0 ? std::sqrt(total.w_sq_err[c] / total.w[c]) : 0.0;
    m.bins[c] = total.n[c];
  }
  m.rel_rmse_mean = (m.rel_rmse[0] + m.rel_rmse[1] + m.rel_rmse[2]) / 3;
  m.log_rmse_mean = (m.log_rmse[0] + m.log_rmse[1] + m.log_rmse[2]) / 3;
  m.cos_rmse_mean = (m.cos_rmse[0] + m.cos_rmse[1] + m.cos_rmse[2]) / 3;
  return m;
}

}  // namespace

BrdfFn nearest_lookup_fn(const BrdfTable& table) {
  const BrdfTable* t = &table;
  return [t](const Vec3& wi, const Vec3& wo, double rgb[3]) { lookup_nearest(*t, wi, wo, rgb); };
}

BrdfMetrics brdf_metrics(const BrdfTable& reference, const BrdfTable& test) {
  return accumulate(reference, 0, [&test](int, int, int, std::size_t idx, double t[3]) {
    for (int c = 0; c < kChannels; ++c) t[c] = test.measured(c, idx) ? test.physical(c, idx) : 0.0;
  });
}

BrdfMetrics brdf_metrics(const BrdfTable& reference, const BrdfFn& test) {
  return accumulate(reference, 0, [&test](int h, int d, int p, std::size_t, double t[3]) {
    Vec3 wi, wo;
    from_half_diff({theta_h_of(h), 0.0, theta_d_of(d), phi_d_of(p)}, &wi, &wo);
    test(wi, wo, t);
  });
}

}  // namespace cbrdf
