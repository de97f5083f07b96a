// SPDX-License-Identifier: MIT
#include "eval/residual_eval.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace cbrdf::internal {

double apply_residual(double base_stored, std::int32_t code, double step, double knee) {
  return apply_residual_value(base_stored, double(code) * step, knee);
}

double apply_residual_value(double base_stored, double residual, double knee) {
  const double y = std::log1p(base_stored / knee) + residual;
  // y <= 0 only below a zero base: the source was >= 0, so clamping at 0 only brings it closer.
  const double v = y > 0.0 ? std::expm1(y) * knee : 0.0;
  constexpr double kMax = std::numeric_limits<double>::max();
  return v < kMax ? v : kMax;
}

void apply_residual_to_table(const Model& model, BrdfTable* table) {
  const Residual& r = model.residual;
  if (!r.present()) return;
  if (r.exact) {
    *table = *r.exact;
    return;
  }
  const NotMeasured& nm = model.not_measured;
  for (int c = 0; c < kChannels; ++c) {
    double* data = table->channel_data(c);
    const std::size_t first = std::size_t(c) * kBinsPerChannel;
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (nm.test(c, i)) continue;
      data[i] = apply_residual_value(data[i], r.value_at(first + i), r.knee);
    }
  }
  double* all = table->stored_values().data();
  for (const ResidualEscape& e : r.escapes) all[e.bin] = e.stored;
}

ResidualEval::ResidualEval(const Model& model)
    : residual_(&model.residual), mask_(&model.not_measured) {}

std::size_t ResidualEval::footprint_bytes() const {
  const Residual& r = *residual_;
  std::size_t n = sizeof(*this) + r.codes.capacity() * sizeof(r.codes[0]) +
                  r.values.capacity() * sizeof(r.values[0]) + r.row_shift.capacity() +
                  r.escapes.capacity() * sizeof(ResidualEscape);
  if (r.exact) n += sizeof(BrdfTable) + r.exact->stored_values().capacity() * sizeof(double);
  return n;
}

double ResidualEval::at_bin(int channel, std::size_t index, double physical) const {
  if (mask_->test(channel, index)) return physical;
  const double scale = kMerlScale[std::size_t(channel)];
  if (residual_->exact) return residual_->exact->physical(channel, index);
  const std::uint32_t bin = std::uint32_t(std::size_t(channel) * kBinsPerChannel + index);
  const auto& esc = residual_->escapes;
  const auto it =
      std::lower_bound(esc.begin(), esc.end(), bin,
                       [](const ResidualEscape& e, std::uint32_t b) { return e.bin < b; });
  if (it != esc.end() && it->bin == bin) return it->stored * scale;
  return apply_residual_value(physical / scale, residual_->value_at(bin), residual_->knee) * scale;
}

namespace {

// The residual (log1p domain) of each channel at a grid position: trilinear between the 8 bins
// around it, theta_h and theta_d clamped to the grid, phi_d periodic over its 180 bins.
void interpolate(const Residual& r, const GridPosition& g, double out[3]) {
  const double h = std::clamp(g.theta_h, 0.0, double(kThetaHBins - 1));
  const double d = std::clamp(g.theta_d, 0.0, double(kThetaDBins - 1));
  const double p = std::clamp(g.phi_d, 0.0, double(kPhiDBins));
  const int h0 = std::min(int(h), kThetaHBins - 2), d0 = std::min(int(d), kThetaDBins - 2);
  const int p0 = std::min(int(p), kPhiDBins - 1);
  const int p1 = p0 + 1 == kPhiDBins ? 0 : p0 + 1;
  const double fh = h - h0, fd = d - d0, fp = p - p0;
  const bool rows = !r.row_shift.empty();
  if (r.interpolated()) {
    for (int c = 0; c < kChannels; ++c) {
      const double* v = r.values.data() + std::size_t(c) * kBinsPerChannel;
      auto row = [&](int i, int j) {
        return v[merl_index(i, j, p0)] * (1 - fp) + v[merl_index(i, j, p1)] * fp;
      };
      const double lo = row(h0, d0) * (1 - fd) + row(h0, d0 + 1) * fd;
      const double hi = row(h0 + 1, d0) * (1 - fd) + row(h0 + 1, d0 + 1) * fd;
      out[c] = lo * (1 - fh) + hi * fh;
    }
    return;
  }
  for (int c = 0; c < kChannels; ++c) {
    const std::int32_t* q = r.codes.data() + std::size_t(c) * kBinsPerChannel;
    // Mode 2 scales each bin by its row's step (the product is exact for mode 0's 1.0).
    auto at = [&](int i, int j, int k) {
      const std::size_t b = merl_index(i, j, k);
      return double(q[b]) * (rows ? r.step_at(b) : 1.0);
    };
    auto row = [&](int i, int j) { return at(i, j, p0) * (1 - fp) + at(i, j, p1) * fp; };
    const double lo = row(h0, d0) * (1 - fd) + row(h0, d0 + 1) * fd;
    const double hi = row(h0 + 1, d0) * (1 - fd) + row(h0 + 1, d0 + 1) * fd;
    out[c] = (lo * (1 - fh) + hi * fh) * (rows ? 1.0 : r.step);
  }
}

// A physical value corrected by a residual of the stored value's log1p.
double apply_log(double physical, double r, double knee, int channel) {
  const double k = knee * kMerlScale[std::size_t(channel)];  // the knee in physical units
  const double y = std::log1p(physical / k) + r;
  const double v = y > 0.0 ? std::expm1(y) * k : 0.0;
  constexpr double kMax = std::numeric_limits<double>::max();
  return v < kMax ? v : kMax;
}

}  // namespace

void ResidualEval::apply(const Vec3& wi, const Vec3& wo, double rgb[3]) const {
  if (!(wi.z > 0.0) || !(wo.z > 0.0)) return;
  if (residual_->exact) {
    lookup_linear(*residual_->exact, wi, wo, rgb);
    return;
  }
  double r[3];
  interpolate(*residual_, grid_position(wi, wo), r);
  for (int c = 0; c < kChannels; ++c) {
    rgb[c] = apply_log(std::max(rgb[c], 0.0), r[c], residual_->knee, c);
  }
}

void ResidualEval::apply(const float wi[3], const float wo[3], float rgb[3]) const {
  if (!(wi[2] > 0.0f) || !(wo[2] > 0.0f)) return;
  const Vec3 a{wi[0], wi[1], wi[2]}, b{wo[0], wo[1], wo[2]};
  double r[3];
  if (residual_->exact) {
    lookup_linear(*residual_->exact, a, b, r);
    for (int c = 0; c < kChannels; ++c) {
      rgb[c] = float(std::min(r[c], double(std::numeric_limits<float>::max())));
    }
    return;
  }
  interpolate(*residual_, grid_position(a, b), r);
  for (int c = 0; c < kChannels; ++c) {
    const double v = apply_log(std::max(double(rgb[c]), 0.0), r[c], residual_->knee, c);
    rgb[c] = float(std::min(v, double(std::numeric_limits<float>::max())));
  }
}

}  // namespace cbrdf::internal
