// One slice of one channel, laid out for fitting: values and mask in [theta_h][theta_d][phi_d]
// order.
#pragma once

#include <cstdint>
#include <vector>

#include "cbrdf/brdf_table.h"

namespace cbrdf::fit {

struct SliceData {
  int nh = kThetaHBins, nd = 0, np = kPhiDBins;
  int theta_d_begin = 0;
  std::vector<double> value;           // physical value; 0 where not measured
  std::vector<std::uint8_t> measured;  // 1 where measured
  // The measured bins as a compact list, for the least-squares passes.
  std::vector<std::uint8_t> mi, mj;
  std::vector<std::uint16_t> mk;
  std::vector<double> mv;
  std::vector<double> mw;  // per measured bin: the loss's weight (1, or cos theta_i cos theta_o)
  // Measured bins of row (i, j) are mi/mj/mk/mv[row_begin[i * nd + j] .. row_begin[i * nd + j +
  // 1]).
  std::vector<std::uint32_t> row_begin;

  std::size_t at(int i, int j, int k) const {
    return (std::size_t(i) * std::size_t(nd) + std::size_t(j)) * std::size_t(np) + std::size_t(k);
  }
  std::size_t size() const { return value.size(); }
  std::size_t measured_count() const { return mv.size(); }
};

// cosine_weights: fill mw with cos(theta_i) cos(theta_o) at each bin's grid directions (else 1).
SliceData extract_slice(const BrdfTable& table, int channel, int theta_d_begin, int theta_d_end,
                        bool cosine_weights = false);

}  // namespace cbrdf::fit
