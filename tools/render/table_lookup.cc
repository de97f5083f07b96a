// SPDX-License-Identifier: MIT
#include "render/table_lookup.h"

#include <algorithm>
#include <cmath>

namespace cbrdf::render {

void lookup_trilinear_measured(const BrdfTable& table, const GridPosition& g, double rgb[3]) {
  if (!(std::isfinite(g.theta_h) && std::isfinite(g.theta_d) && std::isfinite(g.phi_d))) {
    rgb[0] = rgb[1] = rgb[2] = 0.0;
    return;
  }
  const double ph = std::clamp(g.theta_h, 0.0, double(kThetaHBins - 1));
  const double pd = std::clamp(g.theta_d, 0.0, double(kThetaDBins - 1));
  double pp =
      std::fmod(g.phi_d, double(kPhiDBins));  // grid_position folds already; callers may not
  if (pp < 0) pp += kPhiDBins;
  const int h0 = std::min(int(ph), kThetaHBins - 2), d0 = std::min(int(pd), kThetaDBins - 2);
  const int p0 = std::min(int(pp), kPhiDBins - 1);
  const double fh = ph - h0, fd = pd - d0, fp = pp - p0;
  double sum[kChannels] = {}, weight[kChannels] = {};
  for (int a = 0; a < 2; ++a) {
    for (int b = 0; b < 2; ++b) {
      const double wab = (a ? fh : 1 - fh) * (b ? fd : 1 - fd);
      for (int e = 0; e < 2; ++e) {
        const double w = wab * (e ? fp : 1 - fp);
        if (w == 0.0) continue;
        const std::size_t idx = merl_index(h0 + a, d0 + b, (p0 + e) % kPhiDBins);
        for (int c = 0; c < kChannels; ++c) {
          const double s = table.stored(c, idx);
          if (s < 0.0) continue;  // not measured: no weight
          sum[c] += w * s;
          weight[c] += w;
        }
      }
    }
  }
  for (int c = 0; c < kChannels; ++c) {
    rgb[c] = weight[c] > 0 ? sum[c] / weight[c] * kMerlScale[std::size_t(c)] : 0.0;
  }
}

void lookup_trilinear_measured(const BrdfTable& table, const Vec3& wi, const Vec3& wo,
                               double rgb[3]) {
  lookup_trilinear_measured(table, grid_position(wi, wo), rgb);
}

}  // namespace cbrdf::render
