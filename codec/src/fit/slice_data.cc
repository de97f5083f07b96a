#include "fit/slice_data.h"

namespace cbrdf::fit {

SliceData extract_slice(const BrdfTable& table, int channel, int theta_d_begin, int theta_d_end) {
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
      }
    }
  }
  s.row_begin.push_back(std::uint32_t(s.mv.size()));
  return s;
}

}  // namespace cbrdf::fit
