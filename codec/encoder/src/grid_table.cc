// SPDX-License-Identifier: MIT
// tabulate_grid(): one theta_h row per work item.
#include "grid_table.h"

#include <atomic>
#include <cmath>
#include <string>

#include "parallel_for.h"

namespace cbrdf::internal {
namespace {

// Fills theta_h row i. Returns the first index with a non-finite value, or kBinsPerChannel.
std::size_t fill_row(const GridFn& fn, int i, BrdfTable* table) {
  std::size_t bad = kBinsPerChannel;
  HalfDiff hd;
  hd.theta_h = theta_h_of(i);
  for (int j = 0; j < kThetaDBins; ++j) {
    hd.theta_d = theta_d_of(j);
    for (int k = 0; k < kPhiDBins; ++k) {
      const std::size_t idx = merl_index(i, j, k);
      // The mask comes from the generator's own arithmetic, not from the function's directions, so
      // that it matches real files bit for bit even where rounding puts a direction on the horizon.
      if (bin_below_horizon(i, j, k)) {
        table->set_not_measured(idx, -1.0);
        continue;
      }
      hd.phi_d = phi_d_of(k);
      double rgb[3];
      fn(hd, rgb);
      for (int c = 0; c < kChannels; ++c) {
        if (!std::isfinite(rgb[c]) && bad == kBinsPerChannel) bad = idx;
        table->set_physical(c, idx, rgb[c]);
      }
    }
  }
  return bad;
}

}  // namespace

Expected<BrdfTable> tabulate_grid(const GridFn& fn, std::string_view what) {
  BrdfTable table;
  std::atomic<std::size_t> first_bad{kBinsPerChannel};
  // Rows are independent and write disjoint parts of the table; at most 8 threads (memory-bound
  // beyond that).
  parallel_for(kThetaHBins, 8, [&](int i) {
    const std::size_t bad = fill_row(fn, i, &table);
    std::size_t seen = first_bad.load();
    while (bad < seen && !first_bad.compare_exchange_weak(seen, bad)) {
    }
  });
  if (first_bad.load() != kBinsPerChannel) {
    const BinIndex b = merl_bin(first_bad.load());
    return error(ErrorCode::kNumeric, std::string(what) + " is not finite at MERL bin (theta_h " +
                                          std::to_string(b.theta_h) + ", theta_d " +
                                          std::to_string(b.theta_d) + ", phi_d " +
                                          std::to_string(b.phi_d) + ")");
  }
  return table;
}

}  // namespace cbrdf::internal
