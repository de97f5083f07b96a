// SPDX-License-Identifier: MIT
// The contexts of RESD's range-coded codes (spec 4.6, "Range-coded codes"), which the reader
// (residual_codes.cc) and the encoder's writer (residual_codes_writer.cc) share so that both see
// every code in the same context: the classes, the magnitude buckets, the sign contexts and the
// order in which rows are visited.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "cbrdf/model.h"
#include "chunks.h"
#include "range_coder.h"
#include "residual_codes.h"

namespace cbrdf::internal::residual_contexts {

inline constexpr int kClasses =
    7;  // mode 3's coarsest level, then phi_d / theta_d steps of 3 levels
inline constexpr int kBuckets = 11;  // of the neighbours' weighted magnitude
inline constexpr int kContexts = kClasses * kBuckets * 2;
inline constexpr int kSignContexts = 27;
// |q| <= 2^28 has at most 29 bits: exponents 0..28.
inline constexpr int kMaxCodeExponent = 28;
inline constexpr std::size_t kSlab = std::size_t(kThetaDBins) * kPhiDBins;
inline constexpr std::size_t kRowsPerChannel = std::size_t(kThetaHBins) * kThetaDBins;

struct Contexts {
  std::array<internal::FineProb, kMaxCodeExponent + 1> exponent;
  std::array<std::array<internal::FineProb, kMaxCodeExponent>, kMaxCodeExponent + 1> mantissa;
};

struct CodeModel {
  // The zero flags apart, together in a few cache lines: one is read for every bin.
  std::array<internal::FineProb, kContexts> zero;
  std::array<Contexts, kContexts> ctx;
  std::array<internal::FineProb, kSignContexts> sign;
};

// Mode 3's levels (L = 3, the reference writer's) tell apart codes of very different sizes: the
// coarsest nodes, then per level the steps along phi_d and along theta_d. Modes 0 and 2 share the
// classes: they cost nothing there.
inline constexpr std::array<std::uint8_t, 8 * 8> make_class_table() {
  std::array<std::uint8_t, 64> t{};
  for (int d = 0; d < 8; ++d) {
    for (int p = 0; p < 8; ++p) {
      int l = 3;
      while (l > 0 && ((d | p) & ((1 << l) - 1)) != 0) --l;  // min(tz(d), tz(p), 3)
      const int h = 1 << l;
      t[std::size_t(d * 8 + p)] =
          std::uint8_t(l == 3 ? 0 : 1 + 2 * (2 - l) + (d % (2 * h) == 0 ? 0 : 1));
    }
  }
  return t;
}
inline constexpr std::array<std::uint8_t, 64> kClassOf = make_class_table();

// The buckets of s: a bucket is how many of these s exceeds. Counted with compares rather than
// looked up, so a row's loop vectorizes (a table lookup per bin is a gather).
inline constexpr std::int16_t kBucketTops[kBuckets - 1] = {0, 1, 2, 4, 6, 9, 14, 22, 40, 80};
// Capping each magnitude at 81 leaves every bucket as it was (a sum with a term of 81 or more is
// above 80 either way) and keeps the sums in 16 bits (8 to a 128-bit vector).
inline constexpr std::int32_t kCap = 81;

// The context index without its bucket, (class x kBuckets) x 2 + (c > 0), per (c > 0, d mod 8, p).
using RowBase = std::array<std::int16_t, kPhiDBins>;
inline constexpr std::array<std::array<RowBase, 8>, 2> make_row_base() {
  std::array<std::array<RowBase, 8>, 2> t{};
  for (int later = 0; later < 2; ++later) {
    for (int d = 0; d < 8; ++d) {
      for (int p = 0; p < kPhiDBins; ++p) {
        t[std::size_t(later)][std::size_t(d)][std::size_t(p)] =
            std::int16_t(kClassOf[std::size_t(d * 8 + (p & 7))] * kBuckets * 2 + later);
      }
    }
  }
  return t;
}
inline constexpr std::array<std::array<RowBase, 8>, 2> kRowBase = make_row_base();

inline std::uint8_t capped_magnitude(std::int32_t v) {
  const std::int32_t m = v < 0 ? std::int32_t(0u - std::uint32_t(v)) : v;  // INT32_MIN stays < 0
  return std::uint8_t(m < 0 || m > kCap ? kCap : m);
}

// What the contexts read of the codes coded so far: each code's capped magnitude (kMaskBits
// bytes; a byte per code is cheaper to read 180 at a time than the codes themselves) and, per row
// r = (c x 90 + h) x 90 + d, whether it holds a nonzero code.
struct Coded {
  std::vector<std::uint8_t> magnitude = std::vector<std::uint8_t>(kMaskBits, 0);
  std::vector<std::uint8_t> nonzero = std::vector<std::uint8_t>(kChannels * kRowsPerChannel, 0);
};

inline int sign_class(std::int32_t v) {
  return int(v > 0) + 2 * int(v < 0);
}

// The magnitude contexts of row (c, h, d), all 180 at once: s weighs the same bin of the previous
// theta_h slab twice and its phi_d neighbours (phi_d wraps) once, and the same bin of the previous
// channel twice. They read earlier slabs and channels only, never the row itself, so a row's
// contexts are known before its first code (computed inside the coder's loop, a bin's context
// cost a third of the decode). A row of zeros (most rows at coarse bounds) adds nothing, and when
// both rows read are zeros the contexts are the row's base alone. Returns k or that base.
inline const std::int16_t* row_contexts(const Coded& coded, int c, int h, int d, std::int16_t* k) {
  const std::size_t r =
      (std::size_t(c) * kThetaHBins + std::size_t(h)) * kThetaDBins + std::size_t(d);
  const bool up_row = h > 0 && coded.nonzero[r - kThetaDBins] != 0;
  const bool channel_row = c > 0 && coded.nonzero[r - kRowsPerChannel] != 0;
  const RowBase& base = kRowBase[c > 0 ? 1 : 0][std::size_t(d & 7)];
  if (!up_row && !channel_row) return base.data();
  const std::uint8_t* row = coded.magnitude.data() + r * kPhiDBins;
  std::array<std::int16_t, kPhiDBins> s{};
  if (up_row) {
    std::array<std::int16_t, kPhiDBins + 2> a;  // the slab before, with its wrapped ends
    const std::uint8_t* up = row - kSlab;
    for (std::size_t p = 0; p < kPhiDBins; ++p) a[p + 1] = up[p];
    a[0] = a[kPhiDBins];
    a[kPhiDBins + 1] = a[1];
    for (std::size_t p = 0; p < kPhiDBins; ++p) {
      s[p] = std::int16_t(2 * a[p + 1] + a[p] + a[p + 2]);
    }
  }
  if (channel_row) {
    const std::uint8_t* before = row - kBinsPerChannel;
    for (std::size_t p = 0; p < kPhiDBins; ++p) s[p] = std::int16_t(s[p] + 2 * before[p]);
  }
  for (std::size_t p = 0; p < kPhiDBins; ++p) {
    const std::int16_t v = s[p];  // the compares written out: a loop here stops vectorization
    const int b = (v > kBucketTops[0]) + (v > kBucketTops[1]) + (v > kBucketTops[2]) +
                  (v > kBucketTops[3]) + (v > kBucketTops[4]) + (v > kBucketTops[5]) +
                  (v > kBucketTops[6]) + (v > kBucketTops[7]) + (v > kBucketTops[8]) +
                  (v > kBucketTops[9]);
    k[p] = std::int16_t(base[p] + 2 * b);
  }
  return k;
}

// The sign contexts of row (c, h, d): from the signs of the same bin one and two slabs before and
// in the channel before (a row of zeros where there is none).
class SignRows {
 public:
  SignRows(const std::int32_t* q, int c, int h, std::size_t b0)
      : up_(h > 0 ? q + (b0 - kSlab) : kZeros.data()),
        up2_(h > 1 ? q + (b0 - 2 * kSlab) : kZeros.data()),
        channel_(c > 0 ? q + (b0 - kBinsPerChannel) : kZeros.data()) {}
  int context(std::size_t p) const {
    return 9 * sign_class(up_[p]) + 3 * sign_class(channel_[p]) + sign_class(up2_[p]);
  }

 private:
  static constexpr std::array<std::int32_t, kPhiDBins> kZeros{};
  const std::int32_t* up_;
  const std::int32_t* up2_;
  const std::int32_t* channel_;
};

inline std::uint64_t magnitude(std::int32_t v) {
  return v < 0 ? std::uint64_t(-std::int64_t(v)) : std::uint64_t(v);
}

// A row of codes as the coder visits it: its measured bins (phi_d), their magnitude contexts
// and sign contexts, and where its codes sit (MERL index i0 + p, code b0 + p).
struct Row {
  int c;
  std::size_t i0, b0;
  std::span<const std::uint8_t> bins;
  const std::int16_t* k;
  SignRows signs;
};

// Calls f(row) for each row with a measured bin in the spec's order (channel, theta_h, theta_d),
// while f returns true; the contexts read what `coded` holds when the row comes.
template <class F>
bool for_each_row(const std::int32_t* q, const NotMeasured& mask, const Coded& coded, F&& f) {
  std::array<std::int16_t, kPhiDBins> k;
  std::array<std::uint8_t, kPhiDBins> list;
  for (int c = 0; c < kChannels; ++c) {
    for (int h = 0; h < kThetaHBins; ++h) {
      for (int d = 0; d < kThetaDBins; ++d) {
        const std::size_t i0 = (std::size_t(h) * kThetaDBins + std::size_t(d)) * kPhiDBins;
        const std::size_t b0 = std::size_t(c) * kBinsPerChannel + i0;
        const std::span<const std::uint8_t> bins = measured_bins(mask, b0, list);
        if (bins.empty()) continue;
        if (!f(Row{c, i0, b0, bins, row_contexts(coded, c, h, d, k.data()),
                   SignRows(q, c, h, b0)})) {
          return false;
        }
      }
    }
  }
  return true;
}

}  // namespace cbrdf::internal::residual_contexts
