// SPDX-License-Identifier: MIT
// The adaptive binary range coder of container version 1.3 (spec/container.md section 5): LZMA's
// coder (11-bit probabilities, 32-bit range, carry through a cached byte) with the always-zero
// first byte dropped and up to 4 trailing zero bytes trimmed, and the binarizations built on it.
// Small tables of smooth data (a few thousand values) are where zstd's frame and literal costs are
// largest; an adaptive coder with a few contexts learns their statistics within a table. The
// decoding side and the probabilities and contexts both sides adapt alike; the encoding side is the
// encoder's (codec/encoder/src/bitstream/range_encoder.h).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "cbrdf/status.h"

namespace cbrdf::internal {

inline constexpr int kProbBits = 11;
inline constexpr std::uint16_t kProbOne = 1u << kProbBits;
inline constexpr std::uint16_t kProbHalf = kProbOne / 2;
// Adaptation rate: p moves 1/16 of the way to each coded bit (measured against 1/32 on the
// marginal tables of real materials: tables are short, fast adaptation wins).
inline constexpr int kAdaptShift = 4;
// Exp-Golomb exponents above this are refused: 2^24 exceeds every value the format codes.
inline constexpr int kMaxExponent = 24;

// Probability (in 1/2^Bits) that the next bit is 0.
template <int Bits>
struct BasicProb {
  static constexpr int kBits = Bits;
  static constexpr std::uint32_t kOne = 1u << Bits;
  std::uint16_t p = std::uint16_t(kOne / 2);
  void update(int bit) {
    if (bit == 0) {
      p = std::uint16_t(p + ((kOne - p) >> kAdaptShift));
    } else {
      p = std::uint16_t(p - (p >> kAdaptShift));
    }
  }
};
// LZMA's 11 bits: the marginal tables (BASE).
using Prob = BasicProb<kProbBits>;
// 15 bits: the residual layer's codes, whose zero flags are 0 with probability up to 0.9999; 11
// bits cannot go below 15/2048 = 0.7% for a 1 (measured: 10% fewer bytes at E 0.01 on
// beige-fabric's codes).
using FineProb = BasicProb<15>;

// Bounds-checked: bytes past the end read as zero (the writer trims trailing zeros), at most 4 of
// them; finish() reports a stream that needed more, or that left bytes unread.
class Decoder {
 public:
  explicit Decoder(std::span<const std::uint8_t> data);
  // Inline: the decoder's inner loop (about ten calls per table value).
  template <class P>
  int bit(P& prob) {
    const std::uint32_t bound = (range_ >> P::kBits) * prob.p;
    int b = 0;
    if (code_ < bound) {
      range_ = bound;
    } else {
      code_ -= bound;
      range_ -= bound;
      b = 1;
    }
    prob.update(b);
    while (range_ < (1u << 24)) {
      range_ <<= 8;
      code_ = (code_ << 8) | next();
    }
    return b;
  }
  Status finish() const;

 private:
  std::uint8_t next() {
    if (pos_ < data_.size()) return data_[pos_++];
    ++past_end_;
    return 0;
  }
  std::span<const std::uint8_t> data_;
  std::size_t pos_ = 0;
  std::size_t past_end_ = 0;
  std::uint32_t range_ = 0xFFFFFFFFu;
  std::uint32_t code_ = 0;
};

// Contexts of an unsigned Exp-Golomb code: unary exponent bits, then mantissa bits, each adaptive
// by (exponent, position).
struct UIntContexts {
  std::array<Prob, kMaxExponent + 1> exponent{};
  std::array<std::array<Prob, kMaxExponent>, kMaxExponent + 1> mantissa{};
};

// Contexts of a signed value: zero flag, sign, magnitude - 1 as above.
struct SIntContexts {
  Prob zero;
  Prob sign;
  UIntContexts magnitude;
};

// The readers fail (kCorrupt) on an exponent above kMaxExponent: a damaged stream cannot loop.
Status get_uint(Decoder& d, UIntContexts& c, std::uint32_t* out);
Status get_sint(Decoder& d, SIntContexts& c, std::int32_t* out);

}  // namespace cbrdf::internal
