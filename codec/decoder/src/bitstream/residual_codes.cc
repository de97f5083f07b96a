// SPDX-License-Identifier: MIT
#include "residual_codes.h"

#include <array>
#include <memory>
#include <string>

#include "chunks.h"
#include "range_coder.h"

namespace cbrdf::internal {
namespace {

constexpr int kClasses = 7;   // mode 3's coarsest level, then phi_d / theta_d steps of 3 levels
constexpr int kBuckets = 11;  // of the neighbours' weighted magnitude
constexpr int kContexts = kClasses * kBuckets * 2;
constexpr int kSignContexts = 27;
// |q| <= 2^28 has at most 29 bits: exponents 0..28.
constexpr int kMaxCodeExponent = 28;
constexpr std::size_t kSlab = std::size_t(kThetaDBins) * kPhiDBins;

struct Contexts {
  std::array<internal::FineProb, kMaxCodeExponent + 1> exponent;
  std::array<std::array<internal::FineProb, kMaxCodeExponent>, kMaxCodeExponent + 1> mantissa;
};

struct Model {
  // The zero flags apart, together in a few cache lines: one is read for every bin.
  std::array<internal::FineProb, kContexts> zero;
  std::array<Contexts, kContexts> ctx;
  std::array<internal::FineProb, kSignContexts> sign;
};

// Mode 3's levels (L = 3, the reference writer's) tell apart codes of very different sizes: the
// coarsest nodes, then per level the steps along phi_d and along theta_d. Modes 0 and 2 share the
// classes: they cost nothing there.
constexpr std::array<std::uint8_t, 8 * 8> make_class_table() {
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
constexpr std::array<std::uint8_t, 64> kClassOf = make_class_table();

// The bucket of s: how many of 0, 1, 2, 4, 6, 9, 14, 22, 40, 80 it exceeds (a table up to 80,
// the decoder's inner loop).
constexpr std::array<std::uint8_t, 81> make_bucket_table() {
  constexpr std::uint64_t kTop[kBuckets - 1] = {0, 1, 2, 4, 6, 9, 14, 22, 40, 80};
  std::array<std::uint8_t, 81> t{};
  for (std::uint64_t s = 0; s <= 80; ++s) {
    int b = 0;
    while (b < kBuckets - 1 && s > kTop[b]) ++b;
    t[s] = std::uint8_t(b);
  }
  return t;
}
constexpr std::array<std::uint8_t, 81> kBucketOf = make_bucket_table();

inline int bucket(std::uint64_t s) {
  return s <= 80 ? kBucketOf[s] : kBuckets - 1;
}

inline std::uint64_t magnitude(std::int32_t v) {
  return v < 0 ? std::uint64_t(-std::int64_t(v)) : std::uint64_t(v);
}
inline int sign_class(std::int32_t v) {
  return v > 0 ? 1 : v < 0 ? 2 : 0;
}

// The contexts of the code at (c, h, d, p), i = MERL index, from codes coded before it.
struct Neighbours {
  const std::int32_t* q;
  int magnitude_context(int c, int h, int d, int p, std::size_t i) const {
    // Indices are formed before the pointer: own + i - kBinsPerChannel would step outside the
    // array on the way (undefined, and UBSan's pointer-overflow check says so).
    const std::int32_t* own = q + std::size_t(c) * kBinsPerChannel;
    std::uint64_t s = 0;
    if (h > 0) {
      const std::int32_t* row = own + (i - std::size_t(p) - kSlab);
      const int before = p == 0 ? kPhiDBins - 1 : p - 1;
      const int after = p == kPhiDBins - 1 ? 0 : p + 1;
      s += 2 * magnitude(row[p]) + magnitude(row[before]) + magnitude(row[after]);
    }
    if (c > 0) s += 2 * magnitude(q[std::size_t(c - 1) * kBinsPerChannel + i]);
    const int cls = kClassOf[std::size_t((d & 7) * 8 + (p & 7))];
    return (cls * kBuckets + bucket(s)) * 2 + (c > 0 ? 1 : 0);
  }
  int sign_context(int c, int h, std::size_t i) const {
    const std::int32_t* own = q + std::size_t(c) * kBinsPerChannel;
    const int a = h > 0 ? sign_class(own[i - kSlab]) : 0;
    const int b = c > 0 ? sign_class(q[std::size_t(c - 1) * kBinsPerChannel + i]) : 0;
    const int e = h > 1 ? sign_class(own[i - 2 * kSlab]) : 0;
    return 9 * a + 3 * b + e;
  }
};

template <class Sink>
void put_code(Sink& s, Model& m, int k, int sk, std::int32_t v) {
  Contexts& c = m.ctx[std::size_t(k)];
  s.bit(m.zero[std::size_t(k)], v == 0 ? 0 : 1);
  if (v == 0) return;
  s.bit(m.sign[std::size_t(sk)], v < 0 ? 1 : 0);
  const std::uint32_t x = std::uint32_t(magnitude(v));
  int n = 0;
  while ((x >> (n + 1)) != 0) ++n;
  for (int j = 0; j < n; ++j) s.bit(c.exponent[std::size_t(j)], 1);
  s.bit(c.exponent[std::size_t(n)], 0);
  for (int j = n - 1; j >= 0; --j)
    s.bit(c.mantissa[std::size_t(n)][std::size_t(j)], int((x >> j) & 1u));
}

// Visits the measured bins in the spec's order: channel, then MERL index, until f returns false.
template <class F>
void for_each_measured(const NotMeasured& mask, F&& f) {
  std::size_t b = 0;
  for (int c = 0; c < kChannels; ++c) {
    std::size_t i = 0;
    for (int h = 0; h < kThetaHBins; ++h) {
      for (int d = 0; d < kThetaDBins; ++d) {
        for (int p = 0; p < kPhiDBins; ++p, ++i, ++b) {
          if ((mask.bits[b >> 6] >> (b & 63)) & 1u) continue;
          if (!f(c, h, d, p, i)) return;
        }
      }
    }
  }
}

}  // namespace

std::vector<std::uint8_t> encode_residual_codes(const std::int32_t* q, const NotMeasured& mask) {
  auto m = std::make_unique<Model>();
  internal::Encoder e;
  const Neighbours nb{q};
  for_each_measured(mask, [&](int c, int h, int d, int p, std::size_t i) {
    put_code(e, *m, nb.magnitude_context(c, h, d, p, i), nb.sign_context(c, h, i),
             q[std::size_t(c) * kBinsPerChannel + i]);
    return true;
  });
  return e.finish();
}

Status decode_residual_codes(std::span<const std::uint8_t> in, std::uint64_t at,
                             const NotMeasured& mask, std::int32_t* q) {
  auto m = std::make_unique<Model>();
  internal::Decoder dec(in);
  const Neighbours nb{q};
  // The loop of for_each_measured written out: a call per bin cost a third of the decode time.
  Status bad = ok_status();
  std::size_t b = 0;
  for (int c = 0; c < kChannels && bad.ok(); ++c) {
    std::int32_t* own = q + std::size_t(c) * kBinsPerChannel;
    std::size_t i = 0;
    for (int h = 0; h < kThetaHBins && bad.ok(); ++h) {
      for (int d = 0; d < kThetaDBins && bad.ok(); ++d) {
        for (int p = 0; p < kPhiDBins; ++p, ++i, ++b) {
          if ((mask.bits[b >> 6] >> (b & 63)) & 1u) continue;
          const int k = nb.magnitude_context(c, h, d, p, i);
          if (dec.bit(m->zero[std::size_t(k)]) == 0) continue;  // q is zero-filled
          Contexts& cx = m->ctx[std::size_t(k)];
          const int negative = dec.bit(m->sign[std::size_t(nb.sign_context(c, h, i))]);
          int n = 0;
          while (n <= kMaxCodeExponent && dec.bit(cx.exponent[std::size_t(n)]) != 0) ++n;
          if (n > kMaxCodeExponent) {
            bad =
                error(ErrorCode::kCorrupt,
                      std::string("the range-coded code of channel ") + kChannelNames[c] + " bin " +
                          std::to_string(i) + " (stream at payload offset " + std::to_string(at) +
                          ") has an exponent above " + std::to_string(kMaxCodeExponent));
            break;
          }
          std::uint32_t x = 1;
          for (int j = n - 1; j >= 0; --j) {
            x = (x << 1) | std::uint32_t(dec.bit(cx.mantissa[std::size_t(n)][std::size_t(j)]));
          }
          if (x > std::uint32_t(kMaxResidualCode)) {
            bad = error(ErrorCode::kCorrupt, std::string("the range-coded code of channel ") +
                                                 kChannelNames[c] + " bin " + std::to_string(i) +
                                                 " (stream at payload offset " +
                                                 std::to_string(at) + ") is outside -2^28..2^28");
            break;
          }
          own[i] = negative ? -std::int32_t(x) : std::int32_t(x);
        }
      }
    }
  }
  if (!bad.ok()) return bad;
  Status s = dec.finish();
  if (!s.ok()) {
    return s.with_context("range-coded codes at payload offset " + std::to_string(at));
  }
  return ok_status();
}

}  // namespace cbrdf::internal
