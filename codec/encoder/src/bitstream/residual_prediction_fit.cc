// SPDX-License-Identifier: MIT
#include "bitstream/residual_prediction_fit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "bitstream/chunks.h"
#include "byte_writer.h"

namespace cbrdf::internal {
namespace {

constexpr std::size_t kSlab = std::size_t(kThetaDBins) * kPhiDBins;
constexpr int kFeatures = 3;

// A neighbour's code in the bin's step: times 2^delta, delta = the neighbour row's shift minus the
// bin's (floor division for delta < 0); 0 beyond kPredictionShiftLimit.
inline std::int64_t scaled(std::int32_t v, int delta) {
  if (delta > kPredictionShiftLimit || delta < -kPredictionShiftLimit) return 0;
  return delta >= 0 ? std::int64_t(v) * (std::int64_t{1} << delta) : std::int64_t(v) >> -delta;
}

// Calls f(b, channel, group, U', X, XU') for every measured bin b in coding order (channel,
// theta_h, theta_d, phi_d), with the neighbours read from `q` when f is called: the decoder turns q
// into codes in place, so the neighbours are already codes. With phi_step > 1, only the bins whose
// phi_d index is a multiple of it (the fit's sample: every level keeps its share).
template <class F>
void for_each_measured(const std::int32_t* q, const NotMeasured& mask, const Residual& res, F&& f,
                       std::size_t phi_step = 1) {
  const std::vector<std::uint8_t> group = group_table(res);
  for (int c = 0; c < kChannels; ++c) {
    const std::size_t cb = std::size_t(c) * kBinsPerChannel;
    for (int h = 0; h < kThetaHBins; ++h) {
      for (int d = 0; d < kThetaDBins; ++d) {
        const std::size_t row = std::size_t(h) * kThetaDBins + std::size_t(d);
        const int delta = h > 0 ? row_shift_of(res, row - kThetaDBins) - row_shift_of(res, row)
                                : kPredictionShiftLimit + 1;
        for (std::size_t p = 0; p < kPhiDBins; p += phi_step) {
          const std::size_t i = row * kPhiDBins + p, b = cb + i;
          if (mask_bit(mask.bits, b)) continue;
          const std::int64_t u = h > 0 ? scaled(q[b - kSlab], delta) : 0;
          const std::int64_t x = c > 0 ? std::int64_t(q[b - kBinsPerChannel]) : 0;
          const std::int64_t xu =
              c > 0 && h > 0 ? scaled(q[b - kBinsPerChannel - kSlab], delta) : 0;
          f(b, c, int(group[std::size_t(d) * kPhiDBins + p]), u, x, xu);
        }
      }
    }
  }
}

inline std::int64_t prediction(const std::array<std::int16_t, 3>& k, std::int64_t u, std::int64_t x,
                               std::int64_t xu) {
  // |u|, |xu| <= 2^36 and |x| <= 2^28 times |k| <= 2^15: the sum stays below 2^53.
  return (std::int64_t(k[0]) * u + std::int64_t(k[1]) * x + std::int64_t(k[2]) * xu + 128) >> 8;
}

// Solves the n x n system a x = y (Gaussian elimination, partial pivoting); a feature that never
// occurs (a zero pivot) gets 0.
void solve(double a[kFeatures][kFeatures], const double y[kFeatures], int n, double* x) {
  double m[kFeatures][kFeatures + 1];
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) m[i][j] = a[i][j];
    m[i][n] = y[i];
  }
  for (int k = 0; k < n; ++k) {
    int piv = k;
    for (int i = k + 1; i < n; ++i) {
      if (std::abs(m[i][k]) > std::abs(m[piv][k])) piv = i;
    }
    for (int j = 0; j <= n; ++j) std::swap(m[k][j], m[piv][j]);
    if (!(std::abs(m[k][k]) > 1e-9)) continue;
    for (int i = 0; i < n; ++i) {
      if (i == k) continue;
      const double f = m[i][k] / m[k][k];
      for (int j = k; j <= n; ++j) m[i][j] -= f * m[k][j];
    }
  }
  for (int i = 0; i < n; ++i) x[i] = std::abs(m[i][i]) > 1e-9 ? m[i][n] / m[i][i] : 0.0;
}

}  // namespace

void write_prediction(ByteWriter& w, const CodePrediction& p) {
  for (int c = 0; c < kChannels; ++c) {
    for (int g = 0; g < p.groups; ++g) {
      const auto& k = p.at(c, g);
      for (int j = 0; j < (c == 0 ? 1 : kFeatures); ++j) w.u16(std::uint16_t(k[std::size_t(j)]));
    }
  }
}

CodePrediction fit_prediction(const std::int32_t* q, const NotMeasured& mask,
                              const Residual& residual) {
  CodePrediction p;
  p.groups = prediction_groups(residual);
  const std::size_t n = std::size_t(kChannels * p.groups);
  p.coef.assign(n, {0, 0, 0});
  // Least absolute deviations by reweighting: weight 1 / max(1, |miss|) approximates the L1 fit,
  // which follows the bulk of small codes rather than the few largest: fewer bytes than least
  // squares (docs/benchmarks.md).
  std::vector<std::array<double, kFeatures>> k(n, {0, 0, 0});
  // The fit and its check read every kFitPhiStep-th phi_d bin: a quarter of the samples (over a
  // million at full measurement) settle coefficients stored in 1/256, and the writer keeps the
  // predictor only where the whole chunk comes out smaller: files within 0.3% of the full fit's
  // for a quarter of its work (docs/benchmarks.md).
  constexpr std::size_t kFitPhiStep = 4;
  constexpr int kIterations = 6;
  for (int it = 0; it < kIterations; ++it) {
    std::vector<std::array<std::array<double, kFeatures>, kFeatures>> a(n);
    std::vector<std::array<double, kFeatures>> y(n, {0, 0, 0});
    for (auto& m : a) m = {};
    for_each_measured(
        q, mask, residual,
        [&](std::size_t b, int c, int g, std::int64_t u, std::int64_t x, std::int64_t xu) {
          if (u == 0 && x == 0 && xu == 0) return;  // adds nothing to a or y
          const std::size_t s = std::size_t(c * p.groups + g);
          const double f[kFeatures] = {double(u), double(x), double(xu)};
          const double v = double(q[b]);
          double w = 1.0;
          if (it > 0) {
            const double miss = v - (k[s][0] * f[0] + k[s][1] * f[1] + k[s][2] * f[2]);
            w = 1.0 / std::max(1.0, std::abs(miss));
          }
          for (int i = 0; i < kFeatures; ++i) {
            y[s][std::size_t(i)] += w * f[i] * v;
            for (int j = 0; j < kFeatures; ++j) {
              a[s][std::size_t(i)][std::size_t(j)] += w * f[i] * f[j];
            }
          }
        },
        kFitPhiStep);
    for (std::size_t s = 0; s < n; ++s) {
      const int features = s < std::size_t(p.groups) ? 1 : kFeatures;  // R: U only
      double m[kFeatures][kFeatures];
      for (int i = 0; i < kFeatures; ++i) {
        for (int j = 0; j < kFeatures; ++j) m[i][j] = a[s][std::size_t(i)][std::size_t(j)];
      }
      solve(m, y[s].data(), features, k[s].data());
    }
  }
  for (std::size_t s = 0; s < n; ++s) {
    for (int j = 0; j < kFeatures; ++j) {
      const double v = std::nearbyint(k[s][std::size_t(j)] * 256.0);
      p.coef[s][std::size_t(j)] =
          std::isfinite(v) ? std::int16_t(std::clamp(v, -32768.0, 32767.0)) : std::int16_t{0};
    }
  }
  // Keep a group's coefficients only where they lower the sum of log2(1 + |code|) by 1% or more:
  // a fit to codes without relation finds small coefficients that move a few codes by 1 either
  // way, which the proxy cannot tell from a gain.
  std::vector<double> plain(n, 0.0), predicted(n, 0.0);
  for_each_measured(
      q, mask, residual,
      [&](std::size_t b, int c, int g, std::int64_t u, std::int64_t x, std::int64_t xu) {
        const std::size_t s = std::size_t(c * p.groups + g);
        plain[s] += std::log2(1.0 + std::abs(double(q[b])));
        const std::int64_t r = std::int64_t(q[b]) - prediction(p.coef[s], u, x, xu);
        predicted[s] += std::log2(1.0 + std::abs(double(r)));
      },
      kFitPhiStep);
  for (std::size_t s = 0; s < n; ++s) {
    if (!(predicted[s] < 0.99 * plain[s])) p.coef[s] = {0, 0, 0};
  }
  return p;
}

bool predict_codes(const std::int32_t* q, const NotMeasured& mask, const Residual& residual,
                   const CodePrediction& p, std::int32_t* r) {
  std::fill(r, r + kMaskBits, 0);
  bool in_range = true;
  for_each_measured(
      q, mask, residual,
      [&](std::size_t b, int c, int g, std::int64_t u, std::int64_t x, std::int64_t xu) {
        const std::int64_t v = std::int64_t(q[b]) - prediction(p.at(c, g), u, x, xu);
        if (v < -kMaxResidualCode || v > kMaxResidualCode) in_range = false;
        r[b] = std::int32_t(std::clamp<std::int64_t>(v, -kMaxResidualCode, kMaxResidualCode));
      });
  return in_range;
}

}  // namespace cbrdf::internal
