// SPDX-License-Identifier: MIT
// fuzz_roundtrip: encode_model -> decode_model on Models built from the fuzzer's bytes.
//
// Fitting a table is far too slow for a fuzzer (seconds per input), and the codec's contract is
// about Models anyway, so the bytes describe a Model directly: slice bounds, per slice and
// channel a family with a parameter inside its domain (edges, huge and tiny values included), K,
// three marginal tables of assorted shapes (zeros, one-hot, 700-decade ranges, raw doubles), a
// mask (standard, empty, full, runs, flipped bits) and single or per-bin values (NaN payloads
// included), plus the quantization bits, the coding (auto, 1.2 only or 1.3), the metadata's form
// and, on one input in 32, a residual layer (modes 0, 2, 3, 4). The checks are the codec's
// promises (codec.h, spec/container.md 4.3, 4.8): families, parameters, K, bounds, mask and values
// come back bit for bit (in a 1.3 file parameters and K as their binary32 forms); each nonzero
// mass within the documented relative error (e^step - 1; 1.3: e^(2 step) - 1), each zero mass
// exactly; 1.3 is written when asked for and the parameters allow it, never when 1.2 is. One input
// in two (by a byte) breaks one rule of the model instead, and encode_model must then refuse it
// with kInvalidArgument.
//
// The harness lives with the encoder's tests, not in fuzz/ (whose harnesses use the installed
// API only): its model builder and checks use the encoder's internals as their oracle (the
// families' parameter ranges, the binary32 forms BASE stores and whether it can hold a model, the
// residual's interpolated levels, the residual limits).
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "../../fuzz/harness/common.h"
#include "bitstream/chunk_writers.h"
#include "bitstream/residual_levels.h"
#include "cbrdf/codec.h"
#include "cbrdf/container.h"
#include "cbrdf/container_writer.h"
#include "cbrdf/coords.h"
#include "cbrdf/model.h"
#include "copula/registry.h"

namespace cbrdf::fuzz {

// A parameter of the family's range a file may hold (its row in copula/registry.h): raw bits,
// independence, its neighbour, the edges, log-uniform and uniform distances from independence.
inline double pick_theta(CopulaFamily f, ByteSource& in) {
  const std::uint8_t mode = in.u8() % 8;
  const double raw = std::bit_cast<double>(in.u64());
  if (mode == 7 && copula_parameter_valid(f, raw)) return raw;
  const CopulaFamilyRow& row = *family_row(f);
  const double lo = row.search_lo, hi = row.search_hi;
  const double ind = row.copula().domain().independence;
  if (!row.has_parameter()) return ind;
  // The side of independence with more room (Frank's negative one) and the other.
  const double far = hi - ind >= ind - lo ? hi : lo, near = far == hi ? lo : hi;
  // ind +- d rounds, and can land a hair beyond an edge: clamp (the encoder rightly refuses it).
  auto toward = [&](double edge, double d) {
    return std::clamp(edge > ind ? ind + d : ind - d, lo, hi);
  };
  const double span = std::abs(far - ind);
  switch (mode) {
    case 0:
      return ind;
    case 1:
      return toward(far, std::min(span, std::exp(in.in_range(-40.0, std::log(span)))));
    case 2:
      return std::nextafter(ind, far);
    case 3:
      return toward(far, in.in_range(0.0, std::min(span, 10.0)));
    case 4:
      return far;
    case 5:
      return near;
    case 6:
      return near == ind ? toward(far, 1e-300)
                         : toward(near, in.in_range(0.0, std::abs(near - ind)));
    default:
      return toward(far, in.in_range(0.0, span));
  }
}

inline double pick_scale(ByteSource& in) {
  const std::uint8_t mode = in.u8() % 6;
  const double raw = std::bit_cast<double>(in.u64());
  switch (mode) {
    case 0:
      return 0.0;
    case 1:
      return std::numeric_limits<double>::max();
    case 2:
      return 5e-324;
    case 3:
      return std::isfinite(raw) && raw >= 0.0 ? raw : 1.0;
    default:
      return std::exp(in.in_range(-50.0, 50.0));
  }
}

inline std::vector<double> pick_masses(std::size_t n, ByteSource& in) {
  std::vector<double> t(n, 0.0);
  const std::uint8_t kind = in.u8() % 7;
  switch (kind) {
    case 0:
      break;  // all zero
    case 1:
      t[in.u8() % n] = 1.0;
      break;
    case 2: {
      const double k = in.in_range(0.0, 20.0);
      for (std::size_t i = 0; i < n; ++i) t[i] = std::exp(-k * double(i));
      break;
    }
    case 3:
      for (double& m : t) m = in.u8();
      break;
    case 4:
      for (double& m : t) m = std::exp(-3.0 * in.u8());
      break;
    case 5:
      std::fill(t.begin(), t.end(), 0.25);
      break;
    default:
      for (double& m : t) {
        const double raw = std::bit_cast<double>(in.u64());
        m = std::isfinite(raw) && raw >= 0.0 ? raw : 0.0;
      }
      break;
  }
  // The encoder normalizes; an arbitrary overall factor must not matter.
  const double factor = std::ldexp(1.0, int(std::int8_t(in.u8())) * 4);
  std::vector<double> scaled = t;
  for (double& m : scaled) m *= factor;
  if (std::all_of(scaled.begin(), scaled.end(), [](double m) { return std::isfinite(m); })) {
    t = std::move(scaled);
  }
  return t;
}

inline void pick_mask(Model* m, ByteSource& in) {
  NotMeasured& nm = m->not_measured;
  constexpr std::size_t kBits = std::size_t{kChannels} * kBinsPerChannel;
  auto flip = [&](std::size_t b) { nm.bits[b >> 6] ^= std::uint64_t{1} << (b & 63); };
  const std::uint8_t kind = in.u8() % 5;
  if (kind == 0 || kind == 4) {
    // The standard MERL mask, computed once (a million trigonometric evaluations).
    static const NotMeasured standard = [] {
      NotMeasured s;
      for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
        const BinIndex b = merl_bin(i);
        if (bin_below_horizon(b.theta_h, b.theta_d, b.phi_d)) {
          for (int c = 0; c < kChannels; ++c) s.set(c, i);
        }
      }
      return s;
    }();
    nm.bits = standard.bits;
    if (kind == 4) {
      for (int k = in.u8() % 16; k > 0; --k) flip(in.u32() % kBits);
    }
  } else if (kind == 2) {
    std::fill(nm.bits.begin(), nm.bits.end(), ~std::uint64_t{0});
    nm.bits.back() >>= 64 - kBits % 64;  // no bits past the last bin
  } else if (kind == 3) {
    std::size_t pos = 0;
    bool set = false;
    for (int k = 0; k < 64 && pos < kBits && !in.empty(); ++k, set = !set) {
      const std::size_t len =
          std::min<std::size_t>(in.u16() * std::size_t(1 + in.u8() % 4), kBits - pos);
      if (set) {
        for (std::size_t b = pos; b < pos + len; ++b) flip(b);
      }
      pos += len;
    }
  }
  const std::size_t count = nm.count();
  auto negative_or = [](double v, double fallback) { return v >= 0.0 ? fallback : v; };
  const std::uint8_t values = in.u8() % 4;
  // Millions of per-bin values cost a fuzzer input seconds under the sanitizers (the encoder
  // writes them byte by byte); resource_bounds_test round-trips the largest such file.
  if (values <= 1 || count <= 1 || count > 200000) {
    nm.values = {values == 1 ? negative_or(std::bit_cast<double>(in.u64()), -1.0) : -1.0};
    return;
  }
  std::vector<double> pool(8);
  for (double& v : pool) v = negative_or(std::bit_cast<double>(in.u64()), -0.5);
  nm.values.resize(count);
  for (std::size_t i = 0; i < count; ++i) {
    nm.values[i] = values == 2 ? (i % 97 == 3 ? std::numeric_limits<double>::quiet_NaN()
                                              : -0.5 * double(1 + i % 5))
                               : pool[i % pool.size()];
  }
}

// The residual layer (container 1.2, spec 4.6) on one input in 32, from the bytes left after the
// mixtures: mode 0 or 2 (a shift per row), codes that are zero, sparse spikes up to the format's
// limit, a ramp or runs, and a few escapes. Rare because writing it tries each coding of 4.4
// million codes with zstd at level 19: 5 to 140 s per input under the sanitizers on a loaded
// 2-core machine (the fuzzer's timeout is 25 s), against milliseconds for a model without it. So
// it is built only when `allowed`: for one input in kResidualRoundtripEvery (by its hash), and for
// every committed seed in tests/fuzz/fuzz_regression_test.cc (its four residual seeds).
inline constexpr std::uint64_t kResidualRoundtripEvery = 256;
inline void pick_residual(Model* m, ByteSource& in, bool allowed) {
  if (in.empty() || in.u8() % 32 != 0 || !allowed) return;
  constexpr std::size_t kBins = std::size_t{kChannels} * kBinsPerChannel;
  constexpr std::int32_t kMaxCode = std::int32_t{1} << 28;  // spec 4.6: |code| <= 2^28
  Residual& r = m->residual;
  // Clamped: exp(log(16)) rounds to 16.000000000000007, outside the format's range (spec 4.6).
  r.max_error = std::clamp(std::exp(in.in_range(std::log(1e-6), std::log(16.0))), kMinResidualError,
                           kMaxResidualError);
  r.step = 2.0 * r.max_error * in.in_range(0.01, 1.0);
  r.knee =
      std::clamp(std::exp(in.in_range(std::log(1e-12), std::log(1e12))), 1e-12, kMaxResidualKnee);
  r.codes.assign(kBins, 0);
  switch (in.u8() % 4) {
    case 0:
      break;
    case 1:
      for (int k = in.u8(); k > 0; --k) {
        const std::int32_t v = std::int32_t(in.u32() % (2u * kMaxCode + 1)) - kMaxCode;
        r.codes[in.u32() % kBins] = v;
      }
      break;
    case 2:
      for (std::size_t b = 0; b < kBins; ++b) r.codes[b] = std::int32_t(b % 181) - 90;
      break;
    default: {
      std::size_t pos = 0;
      for (int k = 0; k < 32 && pos < kBins && !in.empty(); ++k) {
        const std::size_t len = std::min<std::size_t>(in.u16() * std::size_t{16}, kBins - pos);
        std::fill_n(r.codes.begin() + std::ptrdiff_t(pos), len, std::int32_t(std::int8_t(in.u8())));
        pos += len;
      }
    }
  }
  for (std::size_t b = 0; b < kBins; ++b) {  // not-measured bins carry no code
    if ((m->not_measured.bits[b >> 6] >> (b & 63)) & 1u) r.codes[b] = 0;
  }
  if (in.u8() % 2 == 0) {  // mode 2: every row's bound max_error 2^shift must stay <= 16
    const int top = std::min(in.u8() % 25, int(std::floor(std::log2(16.0 / r.max_error))));
    r.row_shift.resize(std::size_t{kThetaHBins} * kThetaDBins);
    for (std::uint8_t& sh : r.row_shift) sh = std::uint8_t(top > 0 ? in.u8() % (top + 1) : 0);
  }
  // Every residual within the format's +-64 (spec 4.6): codes x step' clamped to it.
  for (std::size_t b = 0; b < kBins; ++b) {
    const double most = std::floor(kMaxResidualValue / r.step_at(b % kBinsPerChannel));
    r.codes[b] = std::int32_t(std::clamp(double(r.codes[b]), -most, most));
  }
  std::vector<std::uint32_t> bins;
  for (int k = in.u8() % 9; k > 0; --k) {
    const std::uint32_t b = in.u32() % std::uint32_t(kBins);
    if (!((m->not_measured.bits[b >> 6] >> (b & 63)) & 1u)) bins.push_back(b);
  }
  std::sort(bins.begin(), bins.end());
  bins.erase(std::unique(bins.begin(), bins.end()), bins.end());
  for (std::uint32_t b : bins) {
    const double raw = std::bit_cast<double>(in.u64());
    r.escapes.push_back({b, std::isfinite(raw) && raw >= 0.0 ? raw : 0.5});
  }
  // Mode 3 (after the escapes, so that older seeds build the models they did): mode 2's codes
  // correcting an interpolation, 1..4 levels, a finest multiplier within the bound limit 16.
  if (!r.row_shift.empty() && !in.empty() && in.u8() % 2 == 0) {
    r.levels = std::uint8_t(1 + in.u8() % 4);
    const double top = std::ldexp(r.max_error, r.max_row_shift());
    const int most = int(std::min(64.0, std::floor(16.0 / top)));
    r.fine_multiplier = std::uint8_t(1 + in.u8() % std::max(most, 1));
    // Mode 4 (version 1.3): a multiplier per level between the finest and the coarsest.
    if (r.levels > 1 && !in.empty() && in.u8() % 2 == 0) {
      for (int l = 1; l < r.levels; ++l) {
        r.middle_multipliers[std::size_t(l - 1)] = std::uint8_t(1 + in.u8() % std::max(most, 1));
      }
    }
    // A rebuilt value sums at most 90 corrections along the coarsest row and a few more down the
    // levels: each |q x step'| <= 0.5 keeps every value well inside +-64.
    for (std::size_t b = 0; b < kBins; ++b) {
      const std::size_t i = b % kBinsPerChannel;
      const double st = r.step_at(i) * double(r.level_multiplier(i));
      const double largest = std::floor(0.5 / st);
      r.codes[b] = std::int32_t(std::clamp(double(r.codes[b]), -largest, largest));
    }
    internal::rebuild_interpolated(&r);
  }
}

// Mode 4 exists only in version 1.3, whose BASE holds each parameter and K as a binary32; the raw
// doubles picked above rarely have one, so nearly every mode 4 model would be refused as one 1.3
// cannot code (none of 22 in 30,000 searched inputs were coded). Such models get binary32 values:
// K's nearest (at most the largest float), the parameter's as 1.3 stores it or independence.
inline void make_base_codable(Model* m) {
  for (Slice& slice : m->slices) {
    for (ChannelSlice& cs : slice.channel) {
      for (int k = 0; k < cs.components(); ++k) {
        Component& comp = cs.component(k);
        comp.scale = double(float(std::min(comp.scale, double(std::numeric_limits<float>::max()))));
        const std::optional<float> theta =
            parameter_f32(std::uint8_t(comp.family), comp.theta, comp.scale);
        comp.theta =
            theta ? double(*theta) : family_row(comp.family)->copula().domain().independence;
      }
    }
  }
}

inline Model build_model(ByteSource& in, bool residual_allowed) {
  Model m;
  std::vector<int> cuts = {0, kThetaDBins};
  const int n_cuts = in.u8() % 16 == 0 ? kThetaDBins - 1 : in.u8() % 8;
  for (int k = 0; k < n_cuts; ++k)
    cuts.push_back(n_cuts == kThetaDBins - 1 ? k + 1 : 1 + in.u8() % 89);
  std::sort(cuts.begin(), cuts.end());
  cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
  for (std::size_t s = 0; s + 1 < cuts.size(); ++s) {
    Slice slice;
    slice.theta_d_begin = cuts[s];
    slice.theta_d_end = cuts[s + 1];
    for (ChannelSlice& cs : slice.channel) {
      cs.family = CopulaFamily(in.u8() % 5);
      cs.theta = pick_theta(cs.family, in);
      cs.scale = pick_scale(in);
      cs.pdf_h = pick_masses(kThetaHBins, in);
      cs.pdf_d = pick_masses(std::size_t(slice.width()), in);
      cs.pdf_p = pick_masses(kPhiDBins, in);
    }
    m.slices.push_back(std::move(slice));
  }
  pick_mask(&m, in);
  // Mixtures (version 1.1) from the bytes left, so that older seeds build the models they did.
  for (Slice& slice : m.slices) {
    for (ChannelSlice& cs : slice.channel) {
      const int extra = in.u8() % 8;
      for (int e = 0; e < extra; ++e) {
        Component comp;
        comp.family = CopulaFamily(in.u8() % 5);
        comp.theta = pick_theta(comp.family, in);
        comp.scale = pick_scale(in);
        comp.pdf_h = pick_masses(kThetaHBins, in);
        comp.pdf_d = pick_masses(std::size_t(slice.width()), in);
        comp.pdf_p = pick_masses(kPhiDBins, in);
        cs.extra.push_back(std::move(comp));
      }
    }
  }
  pick_residual(&m, in, residual_allowed);
  if (m.residual.middle_steps()) make_base_codable(&m);
  return m;
}

// The residual came back bit for bit: bound, step, knee, codes, row shifts and escapes.
inline void check_residual_roundtrip(const Residual& a, const Residual& b, Result* r) {
  r->check(std::memcmp(&a.max_error, &b.max_error, 8) == 0, "the residual bound changed");
  r->check(std::memcmp(&a.step, &b.step, 8) == 0, "the residual step changed");
  r->check(std::memcmp(&a.knee, &b.knee, 8) == 0, "the residual knee changed");
  r->check(a.codes == b.codes, "the residual codes changed");
  r->check(a.row_shift == b.row_shift, "the residual row shifts changed");
  r->check(a.levels == b.levels && a.fine_multiplier == b.fine_multiplier &&
               a.middle_multipliers == b.middle_multipliers,
           "the residual's levels or their multipliers changed");
  // (memcmp of two empty vectors may get null pointers, which it must not.)
  r->check(a.values.size() == b.values.size() &&
               (a.values.empty() ||
                std::memcmp(a.values.data(), b.values.data(), a.values.size() * 8) == 0),
           "the rebuilt interpolated residual changed");
  bool same = a.escapes.size() == b.escapes.size();
  for (std::size_t k = 0; same && k < a.escapes.size(); ++k) {
    same = a.escapes[k].bin == b.escapes[k].bin &&
           std::memcmp(&a.escapes[k].stored, &b.escapes[k].stored, 8) == 0;
  }
  r->check(same, "the residual escapes changed");
}

// Breaks one rule that encode_model documents; returns false when the model stays valid.
inline bool break_model(Model* m, ContainerSettings* s, std::uint8_t how) {
  ChannelSlice& cs = m->slices.front().channel[0];
  NotMeasured& nm = m->not_measured;
  switch (how % 8) {
    case 0:
      cs.pdf_h[0] = -1e-3;
      return true;
    case 1:
      cs.theta = std::numeric_limits<double>::quiet_NaN();
      return true;
    case 2:
      m->slices.back().theta_d_end -= 1;
      return true;
    case 3:
      nm.values[0] = 0.0;
      return true;
    case 4:
      nm.values.resize(nm.count() + 2, -1.0);
      return true;
    case 5:
      cs.scale = -1.0;
      return true;
    case 6:
      cs.pdf_p.pop_back();
      return true;
    default:
      s->bits = how & 8 ? 5 : 17;
      return true;
  }
}

// Each nonzero mass within e^step - 1 of the source's normalized mass (spec 4.3), zeros exact.
// In a 1.3 file (base): within e^(2 step) - 1, step = D / 32 / (2^bits - 2), where the writer's
// span D is at most 8 grid units above the smallest that holds the log masses (spec 4.8).
inline void check_masses(const std::vector<double>& src, const std::vector<double>& dec, int bits,
                         bool base, const std::string& what, Result* r) {
  if (src.size() != dec.size()) {
    r->check(false, what + ": size changed");
    return;
  }
  const double max = *std::max_element(src.begin(), src.end());
  if (!(max > 0.0)) {
    r->check(std::all_of(dec.begin(), dec.end(), [](double v) { return v == 0.0; }),
             what + ": an all-zero table did not decode to zeros");
    return;
  }
  double s = 0.0, min_nz = max;
  for (double m : src) {
    s += m / max;  // scaled by the maximum: cannot overflow
    if (m > 0.0) min_nz = std::min(min_nz, m);
  }
  const double log_s = std::log(s);
  double lo = std::max(std::log(min_nz / max) - log_s, -746.0);
  if (min_nz / max == 0.0) lo = -746.0;  // a ratio below the double range
  const double hi = std::max(-log_s, -746.0);
  // lo and hi are stored as float32 rounded outwards: widen by one float ulp each.
  const double span = hi - lo + (std::abs(lo) + std::abs(hi)) * 0x1p-23;
  const double top = std::ldexp(1.0, bits) - 1.0;
  double bound = std::expm1(span / (top - 1.0));
  if (base) {
    const double units = std::min(std::ceil((hi - std::max(lo, -746.0)) * 32.0) + 8.0, 746.0 * 32);
    bound = std::expm1(2.0 * units / 32.0 / (top - 1.0));
  }
  for (std::size_t i = 0; i < src.size(); ++i) {
    if (src[i] == 0.0) {
      if (dec[i] != 0.0) {
        r->check(false, what + ": a zero mass decoded as " + std::to_string(dec[i]));
        return;
      }
      continue;
    }
    const double want = src[i] / max / s;
    if (want < 1e-290) continue;  // subnormal weights carry no relative precision
    const double rel = std::abs(dec[i] / want - 1.0);
    if (!(rel <= bound * (1.0 + 1e-9) + 1e-12)) {
      r->check(false, what + ": mass " + std::to_string(i) + " has relative error " +
                          std::to_string(rel) + " (normalized " + number_text(want) + ", decoded " +
                          number_text(dec[i]) + ") above the bound " + std::to_string(bound) +
                          " (" + std::to_string(bits) + " bits)");
      return;
    }
  }
}

// base: the file is 1.3 (BASE), whose parameters are binary32 and K binary32 or, where one K
// has no normal binary32, all binary64 (spec 4.8).
inline void check_roundtrip(const Model& a, const Model& b, int bits, bool base, Result* r) {
  if (a.slices.size() != b.slices.size()) {
    r->check(false, "the slice count changed");
    return;
  }
  const bool wide = base && base_wide_scales(a);
  for (std::size_t s = 0; s < a.slices.size(); ++s) {
    const Slice &sa = a.slices[s], &sb = b.slices[s];
    r->check(sa.theta_d_begin == sb.theta_d_begin && sa.theta_d_end == sb.theta_d_end,
             "slice bounds changed");
    for (std::size_t c = 0; c < kChannels; ++c) {
      const ChannelSlice &xc = sa.channel[c], &yc = sb.channel[c];
      const std::string cname = "slice " + std::to_string(s) + " channel " + std::to_string(c);
      if (xc.components() != yc.components()) {
        r->check(false, cname + ": the component count changed");
        continue;
      }
      for (int k = 0; k < xc.components(); ++k) {
        const Component &x = xc.component(k), &y = yc.component(k);
        const std::string name = cname + " component " + std::to_string(k);
        r->check(x.family == y.family, name + ": family changed");
        const double theta =
            base ? double(parameter_f32(std::uint8_t(x.family), x.theta, x.scale).value_or(NAN))
                 : x.theta;
        const double scale = base ? base_scale(x.scale, wide) : x.scale;
        r->check(std::memcmp(&theta, &y.theta, 8) == 0, name + ": parameter changed");
        r->check(std::memcmp(&scale, &y.scale, 8) == 0, name + ": K changed");
        check_masses(x.pdf_h, y.pdf_h, bits, base, name + " theta_h", r);
        check_masses(x.pdf_d, y.pdf_d, bits, base, name + " theta_d", r);
        check_masses(x.pdf_p, y.pdf_p, bits, base, name + " phi_d", r);
      }
    }
  }
  r->check(a.not_measured.bits == b.not_measured.bits, "the mask changed");
  const std::vector<double>&va = a.not_measured.values, &vb = b.not_measured.values;
  r->check(va.size() == vb.size() && std::memcmp(va.data(), vb.data(), 8 * va.size()) == 0,
           "the not-measured values changed");
}

struct RoundtripOptions {
  bool always_residual = false;  // the regression test builds every seed's residual layer
};

inline Result run_roundtrip(Bytes bytes, const RoundtripOptions& options = {}) {
  Result r;
  ByteSource in(bytes);
  ContainerSettings settings;
  settings.bits = 6 + in.u8() % 11;
  settings.zstd_level = 1 + in.u8() % 3;
  // One byte, so that older seeds build the models they did: metadata, its form and the coding
  // (each chosen here, so that a change of the struct's defaults leaves the seeds as they were).
  const std::uint8_t form = in.u8();
  settings.write_metadata = form % 2 == 0;
  settings.format = std::array{ContainerSettings::Format::kAuto, ContainerSettings::Format::kV12,
                               ContainerSettings::Format::kV13}[(form >> 1) % 3];
  settings.metadata =
      (form >> 3) % 2 ? ContainerSettings::Metadata::kShort : ContainerSettings::Metadata::kFull;
  settings.source_name = "fuzz";
  const std::uint8_t breakage = in.u8();
  Model model =
      build_model(in, options.always_residual || input_hash(bytes) % kResidualRoundtripEvery == 0);
  const bool broken = (breakage & 1) && break_model(&model, &settings, std::uint8_t(breakage >> 1));

  Expected<std::vector<std::uint8_t>> file = encode_model(model, settings);
  if (broken) {
    r.check(!file.ok(), "encode_model accepted a model that breaks one of its rules");
    if (!file.ok()) {
      r.reject(file.status(), "encode_model");
      r.check(file.status().code() == ErrorCode::kInvalidArgument,
              "an invalid model was refused with a code other than kInvalidArgument");
    }
    return r;
  }
  if (!file.ok()) {
    r.reject(file.status(), "encode_model");
    // Mode 4 needs version 1.3, which cannot code every model (BASE's ranges, spec 4.8).
    const bool needs_13 =
        model.residual.middle_steps() && file.status().code() == ErrorCode::kInvalidArgument &&
        file.status().message().find("need container version 1.3") != std::string::npos;
    r.check(needs_13, "encode_model refused a valid model: " + file.status().message());
    return r;
  }
  Expected<Model> back = decode_model(*file);
  if (!back.ok()) {
    r.reject(back.status(), "decode_model");
    r.check(false, "the encoder's output does not decode: " + back.status().message());
    return r;
  }
  r.accept();
  Expected<ContainerLayout> version = read_container_version(*file);
  r.check(version.ok(), "the encoder's output has no valid header");
  const bool base = version.ok() && version->minor >= 3;
  // kV13 writes 1.3 wherever BASE can hold the model (its own test: every parameter's binary32).
  r.check(base || settings.format != ContainerSettings::Format::kV13 ||
              !encode_base_chunk(model, settings.bits).has_value(),
          "--format-version 1.3 wrote 1.2 for a model whose parameters have binary32 forms");
  r.check(!base || settings.format != ContainerSettings::Format::kV12, "1.2 only wrote a 1.3 file");
  check_roundtrip(model, *back, settings.bits, base, &r);
  check_residual_roundtrip(model.residual, back->residual, &r);
  // inspect_container decodes the whole file again: one input in eight is enough.
  if (input_hash(bytes) % 8 != 0) return r;
  Expected<ContainerInfo> info = inspect_container(*file);
  r.check(info.ok(), "inspect_container refused the encoder's output");
  if (info.ok()) {
    r.check(info->bits == settings.bits, "bits not recorded");
    r.check(info->not_measured_bins == model.not_measured.count(), "mask count not recorded");
    r.check(info->per_bin_values == (model.not_measured.values.size() != 1),
            "values mode not recorded");
  }
  return r;
}

}  // namespace cbrdf::fuzz
