// SPDX-License-Identifier: MIT
// The noise estimate and the smoothed residual target (noise.h).
#include "cbrdf/noise.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "bitstream/chunks.h"
#include "metrics.h"
#include "residual_encode.h"

namespace cbrdf {
namespace {

// The median of |N(0, 1)|: median |d| / this is the deviation of normal d.
constexpr double kMedianAbsNormal = 0.6744897501960817;
// A band's estimate needs this many runs; fewer (a table measured almost nowhere) reads as 0.
constexpr std::size_t kMinSamples = 200;

double median_sigma(std::vector<double>* v) {
  if (v->size() < kMinSamples) return 0.0;
  auto mid = v->begin() + std::ptrdiff_t(v->size() / 2);
  std::nth_element(v->begin(), mid, v->end());
  return *mid / kMedianAbsNormal;
}

}  // namespace

bool NoiseEstimate::noisy() const {
  return max_sigma() > kNoiseFreeSigma;
}

double NoiseEstimate::max_sigma() const {
  return std::max({sigma[0], sigma[1], sigma[2]});
}

NoiseEstimate estimate_noise(const BrdfTable& table, const NoiseOptions& options) {
  NoiseEstimate est;
  const double norm = 1.0 / std::sqrt(70.0);  // 1 + 16 + 36 + 16 + 1: d has the noise's deviation
  std::vector<double> all, band[kNoiseBands];
  std::vector<double> row(kPhiDBins);
  std::vector<bool> ok(kPhiDBins);
  for (int c = 0; c < kChannels; ++c) {
    all.clear();
    for (auto& b : band) b.clear();
    const double* v = table.channel_data(c);
    for (int th = 0; th < kThetaHBins; ++th) {
      for (int td = 0; td < kThetaDBins; ++td) {
        const double* r = v + merl_index(th, td, 0);
        for (int p = 0; p < kPhiDBins; ++p) {
          // Zeros and not-measured bins have no log; NaN fails the comparison.
          ok[std::size_t(p)] = r[p] > 0 && std::isfinite(r[p]);
          row[std::size_t(p)] = ok[std::size_t(p)] ? std::log(r[p]) : 0.0;
        }
        std::vector<double>& b = band[td / kNoiseBandDegrees];
        for (int p = 2; p + 2 < kPhiDBins; ++p) {
          const auto i = std::size_t(p);
          if (!(ok[i - 2] && ok[i - 1] && ok[i] && ok[i + 1] && ok[i + 2])) continue;
          const double d = (row[i - 2] - 4 * row[i - 1] + 6 * row[i] - 4 * row[i + 1] + row[i + 2]);
          b.push_back(std::abs(d) * norm);
        }
      }
    }
    for (int k = 0; k < kNoiseBands; ++k) {
      all.insert(all.end(), band[k].begin(), band[k].end());
      est.band_sigma[std::size_t(k)][std::size_t(c)] = median_sigma(&band[k]);
    }
    est.samples += all.size();
    est.sigma[std::size_t(c)] = median_sigma(&all);
  }
  double growth = 0;
  int counted = 0;
  for (int c = 0; c < kChannels; ++c) {
    const double first = est.band_sigma.front()[std::size_t(c)];
    const double last = est.band_sigma.back()[std::size_t(c)];
    if (first > 0 && last > 0) {
      growth += last / first;
      ++counted;
    }
  }
  est.grazing_growth = counted > 0 ? growth / counted : 1.0;

  if (options.ceiling) {
    if (!est.noisy()) {
      est.psnr_ceiling_tonemapped = est.psnr_ceiling_linear = kPsnrCapDb;
    } else {
      // Another draw of the estimated noise (seeded: the same table gives the same ceiling).
      BrdfTable other = table;
      std::mt19937_64 rng(0x6e6f697365ULL);
      std::normal_distribution<double> normal(0.0, 1.0);
      for (int c = 0; c < kChannels; ++c) {
        double* v = other.channel_data(c);
        for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
          const double z = normal(rng);
          if (!(v[i] > 0 && std::isfinite(v[i]))) continue;
          const int td = merl_bin(i).theta_d;
          v[i] *= std::exp(est.band_sigma[std::size_t(td / kNoiseBandDegrees)][std::size_t(c)] * z);
        }
      }
      SphereSetup setup;
      setup.threads = options.threads;
      const ImageMetrics m = sphere_psnr(table, other, setup);
      // Noise of many decades per bin (a table of values log-uniform over 1e-30..1e30) takes the
      // other draw's renders past float's range: the PSNR is -inf or NaN, which says nothing
      // about the table. It is not measurable: NaN.
      const auto measured = [](double db) {
        return std::isfinite(db) ? db : std::numeric_limits<double>::quiet_NaN();
      };
      est.psnr_ceiling_tonemapped = measured(m.psnr_tonemapped);
      est.psnr_ceiling_linear = measured(m.psnr_linear);
    }
  }
  return est;
}

BrdfTable smooth_residual_target(const BrdfTable& table, const BrdfTable& base, double knee,
                                 double radius) {
  BrdfTable out = table;
  if (!(radius > 0) || !(knee > 0)) return out;
  const int reach = std::max(1, int(std::ceil(3 * radius)));
  std::vector<double> kernel(std::size_t(2 * reach + 1));
  for (int k = -reach; k <= reach; ++k) {
    kernel[std::size_t(k + reach)] = std::exp(-0.5 * double(k * k) / (radius * radius));
  }
  const auto u = [knee](double x) { return std::log1p(x / knee); };
  constexpr std::size_t kPlane = std::size_t{kThetaDBins} * kPhiDBins;
  // Weighted sums over one theta_h plane: ratio * weight, weight (1 measured, 0 not).
  std::vector<double> r(kPlane), w(kPlane), tr(kPlane), tw(kPlane);
  for (int c = 0; c < kChannels; ++c) {
    const double* src = table.channel_data(c);
    const double* b = base.channel_data(c);
    double* dst = out.channel_data(c);
    for (int th = 0; th < kThetaHBins; ++th) {
      const std::size_t o = merl_index(th, 0, 0);
      for (std::size_t i = 0; i < kPlane; ++i) {
        const bool m = src[o + i] >= 0 && std::isfinite(src[o + i]) && b[o + i] >= 0;
        w[i] = m ? 1.0 : 0.0;
        r[i] = m ? u(src[o + i]) - u(b[o + i]) : 0.0;
      }
      // Along phi_d (within a theta_d row), then along theta_d (within a phi_d column).
      for (int td = 0; td < kThetaDBins; ++td) {
        for (int p = 0; p < kPhiDBins; ++p) {
          double sr = 0, sw = 0;
          for (int k = std::max(-reach, -p); k <= reach && p + k < kPhiDBins; ++k) {
            const std::size_t j = std::size_t(td * kPhiDBins + p + k);
            const double g = kernel[std::size_t(k + reach)];
            sr += g * r[j];
            sw += g * w[j];
          }
          tr[std::size_t(td * kPhiDBins + p)] = sr;
          tw[std::size_t(td * kPhiDBins + p)] = sw;
        }
      }
      for (int td = 0; td < kThetaDBins; ++td) {
        for (int p = 0; p < kPhiDBins; ++p) {
          const std::size_t i = std::size_t(td * kPhiDBins + p);
          if (w[i] == 0) continue;
          double sr = 0, sw = 0;
          for (int k = std::max(-reach, -td); k <= reach && td + k < kThetaDBins; ++k) {
            const std::size_t j = std::size_t((td + k) * kPhiDBins + p);
            const double g = kernel[std::size_t(k + reach)];
            sr += g * tr[j];
            sw += g * tw[j];
          }
          const double ratio = sw > 0 ? sr / sw : 0.0;
          dst[o + i] = std::max(0.0, knee * std::expm1(u(b[o + i]) + ratio));
        }
      }
    }
  }
  return out;
}

}  // namespace cbrdf

namespace cbrdf {

BrdfTable noise_floor_source(const BrdfTable& table, const BrdfTable& base) {
  return smooth_residual_target(table, base, internal::residual_knee(table), kDenoiseRadius);
}

double noise_floor_error(const NoiseEstimate& estimate) {
  // A file holds bounds up to kMaxResidualError: noise beyond it (tens of e-folds per bin) leaves
  // nothing a coarser bound would code.
  return std::min(kFloorPerSigma * estimate.max_sigma(), kMaxResidualError);
}

}  // namespace cbrdf
