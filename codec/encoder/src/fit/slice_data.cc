// SPDX-License-Identifier: MIT
#include "fit/slice_data.h"

#include <algorithm>
#include <cmath>

#include "cbrdf/coords.h"

namespace cbrdf::internal {

namespace {

// cos(theta_i) cos(theta_o) at every bin's grid directions (phi_h = 0), computed once.
const std::vector<float>& cosine_weight_table() {
  static const std::vector<float> table = [] {
    std::vector<float> w(kBinsPerChannel);
    for (std::size_t idx = 0; idx < kBinsPerChannel; ++idx) {
      const BinIndex b = merl_bin(idx);
      Vec3 wi, wo;
      from_half_diff(HalfDiff{theta_h_of(b.theta_h), 0.0, theta_d_of(b.theta_d), phi_d_of(b.phi_d)},
                     &wi, &wo);
      w[idx] = float(std::max(0.0, wi.z) * std::max(0.0, wo.z));
    }
    return w;
  }();
  return table;
}

}  // namespace

SliceData extract_slice(const BrdfTable& table, int channel, int theta_d_begin, int theta_d_end,
                        bool cosine_weights) {
  const float* weights = cosine_weights ? cosine_weight_table().data() : nullptr;
  SliceData s;
  s.nd = theta_d_end - theta_d_begin;
  s.theta_d_begin = theta_d_begin;
  s.value.assign(std::size_t(s.nh) * s.nd * s.np, 0.0);
  s.measured.assign(s.value.size(), 0);
  s.row_begin.reserve(std::size_t(s.nh) * s.nd + 1);
  s.mi.reserve(s.value.size());
  s.mj.reserve(s.value.size());
  s.mk.reserve(s.value.size());
  s.mv.reserve(s.value.size());
  s.mw.reserve(s.value.size());
  const double scale = kMerlScale[std::size_t(channel)];
  const double* data = table.channel_data(channel);
  for (int i = 0; i < s.nh; ++i) {
    for (int j = 0; j < s.nd; ++j) {
      s.row_begin.push_back(std::uint32_t(s.mv.size()));
      const double* src = data + merl_index(i, theta_d_begin + j, 0);
      for (int k = 0; k < s.np; ++k) {
        if (!(src[k] >= 0.0)) continue;
        const double v = src[k] * scale;
        const std::size_t dst = s.at(i, j, k);
        s.value[dst] = v;
        s.measured[dst] = 1;
        s.mi.push_back(std::uint8_t(i));
        s.mj.push_back(std::uint8_t(j));
        s.mk.push_back(std::uint16_t(k));
        s.mv.push_back(v);
        s.mw.push_back(weights ? double(weights[merl_index(i, theta_d_begin + j, k)]) : 1.0);
      }
    }
  }
  s.row_begin.push_back(std::uint32_t(s.mv.size()));
  return s;
}

void normalize_slice(SliceData* s) {
  double largest = 0;
  for (double v : s->mv) largest = std::max(largest, v);
  if (!(largest > 0) || !std::isfinite(largest)) return;
  const int e = std::ilogb(largest);
  const int e3 = 3 * (e >= 0 ? e / 3 : -((2 - e) / 3));  // floor(e / 3) * 3
  if (e3 == 0) return;
  // Scaling by a power of two is one correctly rounded product, so a multiply by 2^-e3 gives
  // ldexp's result (subnormals included) wherever 2^-e3 is itself a normal double.
  if (e3 > -1022 && e3 < 1022) {
    const double f = std::ldexp(1.0, -e3);
    for (double& v : s->value) v *= f;
    for (double& v : s->mv) v *= f;
  } else {
    for (double& v : s->value) v = std::ldexp(v, -e3);
    for (double& v : s->mv) v = std::ldexp(v, -e3);
  }
  s->unit = std::ldexp(s->unit, e3);
}

}  // namespace cbrdf::internal
