// SPDX-License-Identifier: MIT
#include "residual_levels.h"

#include <algorithm>
#include <cmath>

#include "chunks.h"

namespace cbrdf::internal {
namespace {

constexpr int kRows = kThetaDBins;  // a slab: theta_d rows of kPhiDBins bins
constexpr int kCols = kPhiDBins;

// One (channel, theta_h) slab. `step[d]` is row d's step; level l's is times `multiplier[l]`.
struct Slab {
  const double* step;
  const double* multiplier;
  std::int32_t* codes;
  const double* target;  // null when decoding
  double* values;
  int levels;

  // The bin at (d, p) of level l from its prediction: decode its code, or choose it (encoding).
  void visit(int d, int p, int l, double prediction) {
    const std::size_t i = std::size_t(d) * kCols + std::size_t(p);
    const double st = l == levels ? step[d] : step[d] * multiplier[l];
    if (target) codes[i] = residual_code(target[i] - prediction, st);
    values[i] = prediction + double(codes[i]) * st;
  }
  double at(int d, int p) const { return values[std::size_t(d) * kCols + std::size_t(p)]; }
};

// The midpoint prediction between the bins s before and s after, along phi_d (periodic: phi_d
// 180 is phi_d 0 by reciprocity) or theta_d (the last row past 89 repeats the one before).
void run_slab(Slab& s) {
  const int top = 1 << s.levels;
  // Coarsest level: each from the previous node of its row (0 for the first).
  for (int d = 0; d < kRows; d += top) {
    double previous = 0.0;
    for (int p = 0; p < kCols; p += top) {
      s.visit(d, p, s.levels, previous);
      previous = s.at(d, p);
    }
  }
  for (int h = top / 2, l = s.levels - 1; h >= 1; h /= 2, --l) {
    // Along phi_d, on rows that are multiples of 2h.
    for (int d = 0; d < kRows; d += 2 * h) {
      for (int p = h; p < kCols; p += 2 * h) {
        // With at most 4 levels p + h never passes 180: 180 is a multiple of 4, and of the
        // coarsest spacing's half beyond it.
        const int after = p + h == kCols ? 0 : p + h;
        s.visit(d, p, l, 0.5 * (s.at(d, p - h) + s.at(d, after)));
      }
    }
    // Along theta_d, on every h-th column.
    for (int d = h; d < kRows; d += 2 * h) {
      for (int p = 0; p < kCols; p += h) {
        s.visit(d, p, l, d + h < kRows ? 0.5 * (s.at(d - h, p) + s.at(d + h, p)) : s.at(d - h, p));
      }
    }
  }
}

}  // namespace

void interpolate_levels(const double* target, Residual* r) {
  r->values.assign(kMaskBits, 0.0);
  double multiplier[kMaxResidualLevels];  // per level below the coarsest
  for (int l = 0; l < r->levels; ++l) multiplier[l] = double(r->multiplier_of_level(l));
  double step[kRows];
  for (int c = 0; c < kChannels; ++c) {
    for (int h = 0; h < kThetaHBins; ++h) {
      const std::size_t first = std::size_t(h) * kRows * kCols;
      for (int d = 0; d < kRows; ++d) step[d] = r->step_at(first + std::size_t(d) * kCols);
      const std::size_t at = std::size_t(c) * kBinsPerChannel + first;
      Slab s{step,
             multiplier,
             r->codes.data() + at,
             target ? target + at : nullptr,
             r->values.data() + at,
             r->levels};
      run_slab(s);
    }
  }
}

void rebuild_interpolated(Residual* residual) {
  interpolate_levels(nullptr, residual);
}

}  // namespace cbrdf::internal
