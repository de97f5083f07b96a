// SPDX-License-Identifier: MIT
// The encoding side of container 1.3's adaptive binary range coder (spec/container.md section 5;
// the decoder and the contexts both sides share are bitstream/range_coder.h): the encoder, a cost
// meter that adapts the same probabilities without writing, and the binarizations' writers.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "bitstream/range_coder.h"

namespace cbrdf::internal {

class Encoder {
 public:
  template <class P>
  void bit(P& prob, int b) {
    const std::uint32_t bound = (range_ >> P::kBits) * prob.p;
    if (b == 0) {
      range_ = bound;
    } else {
      low_ += bound;
      range_ -= bound;
    }
    prob.update(b);
    while (range_ < (1u << 24)) {
      range_ <<= 8;
      shift_low();
    }
  }
  // Flushes and returns the bytes (first byte dropped, up to 4 trailing zeros trimmed).
  std::vector<std::uint8_t> finish();

 private:
  void shift_low();
  std::uint64_t low_ = 0;
  std::uint32_t range_ = 0xFFFFFFFFu;
  std::uint8_t cache_ = 0;
  std::uint64_t cache_size_ = 1;
  std::vector<std::uint8_t> out_;
};

// Accumulates the cost in bits of what an Encoder would write, adapting the same probabilities:
// the writer's way of choosing between codings before writing one.
class CostMeter {
 public:
  template <class P>
  void bit(P& prob, int b) {
    const double p0 = double(prob.p) / double(P::kOne);
    bits_ -= std::log2(b == 0 ? p0 : 1.0 - p0);
    prob.update(b);
  }
  double bits() const { return bits_; }

 private:
  double bits_ = 0.0;
};

// v >= 0, v < 2^kMaxExponent - 1: n = bit length of v + 1, minus 1, in unary (n ones, a zero),
// then the n bits of v + 1 below its top bit, most significant first.
template <class Sink>
void put_uint(Sink& s, UIntContexts& c, std::uint32_t v) {
  const std::uint32_t x = v + 1;
  int n = 0;
  while ((x >> (n + 1)) != 0) ++n;
  for (int i = 0; i < n; ++i) s.bit(c.exponent[std::size_t(i)], 1);
  s.bit(c.exponent[std::size_t(n)], 0);
  for (int i = n - 1; i >= 0; --i) {
    s.bit(c.mantissa[std::size_t(n)][std::size_t(i)], int((x >> i) & 1u));
  }
}

template <class Sink>
void put_sint(Sink& s, SIntContexts& c, std::int32_t v) {
  s.bit(c.zero, v == 0 ? 0 : 1);
  if (v == 0) return;
  s.bit(c.sign, v < 0 ? 1 : 0);
  const std::uint32_t m = v < 0 ? std::uint32_t(-std::int64_t(v)) : std::uint32_t(v);
  put_uint(s, c.magnitude, m - 1);
}

}  // namespace cbrdf::internal
