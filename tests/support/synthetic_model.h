// SPDX-License-Identifier: MIT
// Hand-built copula Models for the container and codec tests: realistic marginal shapes (smooth
// lobes, near-mirror peaks spanning 12 decades), every family, and the standard MERL mask.
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <vector>

#include "cbrdf/coords.h"
#include "cbrdf/model.h"

namespace cbrdf::testing {

inline void normalize(std::vector<double>* t) {
  double s = 0.0;
  for (double v : *t) s += v;
  for (double& v : *t) v /= s;
}

// A specular lobe in theta_h of width `sigma` (radians) over a diffuse floor `floor`.
inline std::vector<double> lobe_theta_h(double sigma, double floor) {
  std::vector<double> t(kThetaHBins);
  for (int i = 0; i < kThetaHBins; ++i) {
    const double th = theta_h_of(i);
    // Mass of the bin: density times the bin's solid-angle-ish width on the sqrt grid.
    const double width = theta_h_of(i + 0.5) - theta_h_of(std::max(0.0, i - 0.5));
    t[std::size_t(i)] =
        (std::exp(-th * th / (sigma * sigma)) + floor) * width * std::sin(th + 0.01);
  }
  normalize(&t);
  return t;
}

// Near-mirror: 3 bins hold almost everything, 1e-12 elsewhere.
inline std::vector<double> peaked_theta_h() {
  std::vector<double> t(kThetaHBins, 1e-12);
  t[0] = 0.5;
  t[1] = 0.3;
  t[2] = 0.2;
  normalize(&t);
  return t;
}

inline std::vector<double> smooth_theta_d(int begin, int end, double k) {
  std::vector<double> t;
  for (int j = begin; j < end; ++j) t.push_back(1.0 + k * std::cos(theta_d_of(j)) + 0.2 * j / 90.0);
  normalize(&t);
  return t;
}

inline std::vector<double> smooth_phi_d(double k) {
  std::vector<double> t(kPhiDBins);
  for (int p = 0; p < kPhiDBins; ++p) t[std::size_t(p)] = 1.0 + k * std::cos(2.0 * phi_d_of(p));
  normalize(&t);
  return t;
}

inline void set_standard_mask(Model* m, double value = -1.0) {
  m->not_measured = NotMeasured{};
  for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
    const BinIndex b = merl_bin(i);
    if (bin_below_horizon(b.theta_h, b.theta_d, b.phi_d)) {
      for (int c = 0; c < kChannels; ++c) m->not_measured.set(c, i);
    }
  }
  m->not_measured.values = {value};
}

// A model with the given theta_d slice boundaries (first 0, last 90). `peaked` gives channel G a
// near-mirror theta_h marginal; families cycle through all five.
inline Model make_model(const std::vector<int>& bounds, bool peaked = false,
                        std::uint32_t seed = 1) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Model m;
  for (std::size_t s = 0; s + 1 < bounds.size(); ++s) {
    Slice slice;
    slice.theta_d_begin = bounds[s];
    slice.theta_d_end = bounds[s + 1];
    for (int c = 0; c < kChannels; ++c) {
      ChannelSlice& cs = slice.channel[std::size_t(c)];
      switch ((s * 3 + std::size_t(c)) % 5) {
        case 0:
          cs.family = CopulaFamily::kFrank;
          cs.theta = -1.0 - 20.0 * u(rng);
          break;
        case 1:
          cs.family = CopulaFamily::kClayton;
          cs.theta = 0.1 + 3.0 * u(rng);
          break;
        case 2:
          cs.family = CopulaFamily::kGumbel;
          cs.theta = 1.0 + 2.0 * u(rng);
          break;
        case 3:
          cs.family = CopulaFamily::kJoe;
          cs.theta = 1.0 + 2.0 * u(rng);
          break;
        default:
          cs.family = CopulaFamily::kIndependence;
          cs.theta = 0.0;
          break;
      }
      cs.scale = 10.0 + 1000.0 * u(rng);
      cs.pdf_h =
          (peaked && c == 1) ? peaked_theta_h() : lobe_theta_h(0.05 + 0.3 * u(rng), 1e-4 * (1 + c));
      cs.pdf_d = smooth_theta_d(slice.theta_d_begin, slice.theta_d_end, 0.5 * u(rng));
      cs.pdf_p = smooth_phi_d(0.8 * u(rng));
    }
    m.slices.push_back(slice);
  }
  set_standard_mask(&m);
  return m;
}

// make_model with further components: slice channel (s, c) gets (s + c) % max_components extra
// components, each a lobe of its own with a Frank parameter and a smaller scale.
inline Model make_mixture_model(const std::vector<int>& bounds, int max_components,
                                std::uint32_t seed = 1) {
  Model m = make_model(bounds, false, seed);
  std::mt19937 rng(seed + 1000);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (std::size_t s = 0; s < m.slices.size(); ++s) {
    Slice& slice = m.slices[s];
    for (int c = 0; c < kChannels; ++c) {
      ChannelSlice& cs = slice.channel[std::size_t(c)];
      const int extra = int(s + std::size_t(c)) % max_components;
      for (int e = 0; e < extra; ++e) {
        Component comp;
        comp.family = e % 2 == 0 ? CopulaFamily::kFrank : CopulaFamily::kClayton;
        comp.theta = e % 2 == 0 ? -0.5 - 5.0 * u(rng) : 0.2 + u(rng);
        comp.scale = cs.scale * (0.05 + 0.3 * u(rng));
        comp.pdf_h = lobe_theta_h(0.02 + 0.1 * u(rng), 1e-6);
        comp.pdf_d = smooth_theta_d(slice.theta_d_begin, slice.theta_d_end, 0.9 * u(rng));
        comp.pdf_p = smooth_phi_d(0.9 * u(rng));
        cs.extra.push_back(std::move(comp));
      }
    }
  }
  return m;
}

// The golden files' residual layer (mode 0, bound 0.004, knee 1e-4): sparse codes of both signs,
// -6 to 6, at every 4099th bin (offset by channel) that is measured.
inline void add_sparse_residual(Model* m) {
  Residual& r = m->residual;
  r.max_error = 0.004;
  r.step = 0.0079;
  r.knee = 1e-4;
  r.codes.assign(std::size_t(kChannels) * kBinsPerChannel, 0);
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (!m->not_measured.test(c, i) && (i + std::size_t(c)) % 4099 == 0) {
        r.codes[std::size_t(c) * kBinsPerChannel + i] = std::int32_t(i % 13) - 6;
      }
    }
  }
}

inline const std::vector<int>& six_slices() {
  static const std::vector<int> b = {0, 6, 15, 30, 50, 70, 90};
  return b;
}

// The six-slice model with a near-mirror theta_h peak, prepared once per test process.
inline const ModelEvaluator& peaked_evaluator() {
  static const ModelEvaluator e(make_model(six_slices(), /*peaked=*/true));
  return e;
}

// The unit direction at polar angle theta and azimuth phi, both in degrees (z is the normal).
inline Vec3 direction_deg(double theta_deg, double phi_deg) {
  const double t = theta_deg * std::numbers::pi / 180, p = phi_deg * std::numbers::pi / 180;
  return {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
}

// FNV-1a over the bit patterns of everything a decoded model holds (the golden files' pinned
// hashes).
inline std::uint64_t model_hash(const Model& m) {
  std::uint64_t h = 1469598103934665603ull;
  auto mix = [&](std::uint64_t v) {
    for (int i = 0; i < 8; ++i) {
      h ^= (v >> (8 * i)) & 0xFF;
      h *= 1099511628211ull;
    }
  };
  for (const Slice& s : m.slices) {
    mix(std::uint64_t(s.theta_d_end));
    for (const ChannelSlice& c : s.channel) {
      for (int k = 0; k < c.components(); ++k) {
        const Component& comp = c.component(k);
        mix(std::uint64_t(comp.family));
        mix(std::bit_cast<std::uint64_t>(comp.theta));
        mix(std::bit_cast<std::uint64_t>(comp.scale));
        for (const std::vector<double>* t : {&comp.pdf_h, &comp.pdf_d, &comp.pdf_p}) {
          for (double v : *t) mix(std::bit_cast<std::uint64_t>(v));
        }
      }
    }
  }
  for (std::uint64_t w : m.not_measured.bits) mix(w);
  for (std::int32_t q : m.residual.codes) mix(std::uint64_t(std::int64_t(q)));
  return h;
}

}  // namespace cbrdf::testing
