// SPDX-License-Identifier: MIT
// The exact table coding's writer (spec: "Exact table coding"; the reader, and why the coding has
// this shape, are the decoder's bitstream/exact_table.cc): per row the predictor whose integer
// differences of bit patterns leave the smallest residuals, their size symbols to zstd split by
// context and their low bits as they are.
#include "bitstream/exact_table_writer.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>

#include "bitstream/exact_table_coding.h"
#include "byte_writer.h"
#include "parallel_for.h"
#include "zstd_util.h"

namespace cbrdf::internal {
namespace {

using namespace exact_coding;

class BitWriter {
 public:
  void put(std::uint64_t v, int n) {
    while (n > 32) {
      put32(v & 0xFFFFFFFFu, 32);
      v >>= 32;
      n -= 32;
    }
    put32(v, n);
  }
  std::vector<std::uint8_t> finish() {
    while (bits_ > 0) flush_byte();
    return std::move(out_);
  }

 private:
  void put32(std::uint64_t v, int n) {
    acc_ |= v << bits_;
    bits_ += n;
    while (bits_ >= 8) flush_byte();
  }
  void flush_byte() {
    out_.push_back(std::uint8_t(acc_));
    acc_ >>= 8;
    bits_ = bits_ >= 8 ? bits_ - 8 : 0;
  }
  std::uint64_t acc_ = 0;
  int bits_ = 0;
  std::vector<std::uint8_t> out_;
};

// ---- streams: u8 form (0 stored, 1 zstd), u32 content bytes, u32 stored bytes, bytes ----------

void put_stream(ByteWriter* w, std::span<const std::uint8_t> content, int level) {
  auto packed = zstd_compress(content, level);
  const bool use_zstd = packed.ok() && packed->size() < content.size();
  const std::span<const std::uint8_t> stored =
      use_zstd ? std::span<const std::uint8_t>(*packed) : content;
  w->u8(use_zstd ? 1 : 0);
  w->u32(std::uint32_t(content.size()));
  w->u32(std::uint32_t(stored.size()));
  w->bytes(stored);
}

// One channel's bit patterns with each exception (sign bit set) replaced by the working value
// before it (0 for the first bin), so that predictions run smoothly across not-measured bins.
std::vector<std::uint64_t> working_values(const double* v) {
  std::vector<std::uint64_t> w(kBinsPerChannel);
  std::uint64_t prev = 0;
  for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
    const auto bits = std::bit_cast<std::uint64_t>(v[i]);
    w[i] = is_exception(bits) ? prev : bits;
    prev = w[i];
  }
  return w;
}

// Applies (1 - z)^min(n, position) along one axis (0 theta_h, 1 theta_d, 2 phi_d), in place and
// modulo 2^64. Going down the index keeps each pass reading its predecessor's values.
void difference(std::vector<std::uint64_t>* a, int axis, int n) {
  const std::size_t stride = axis == 0 ? kPlaneStride : axis == 1 ? kPhiDBins : 1;
  std::uint64_t* v = a->data();
  for (int t = 1; t <= n; ++t) {
    for (int h = kThetaHBins - 1; h >= 0; --h) {
      for (int d = kThetaDBins - 1; d >= 0; --d) {
        const int pos_hd = axis == 0 ? h : d;
        const std::size_t row = merl_index(h, d, 0);
        for (int p = kPhiDBins - 1; p >= 0; --p) {
          if ((axis == 2 ? p : pos_hd) >= t)
            v[row + std::size_t(p)] -= v[row + std::size_t(p) - stride];
        }
      }
    }
  }
}

struct ChannelPlan {
  std::vector<std::uint64_t> residual;  // per bin, modulo 2^64
  std::vector<std::uint8_t> choice;     // predictor per row
};

// The predictor per row that minimizes the summed residual sizes over the row's coded bins.
ChannelPlan plan_channel(const std::vector<std::uint64_t>& w, const double* v) {
  ChannelPlan plan{std::vector<std::uint64_t>(kBinsPerChannel),
                   std::vector<std::uint8_t>(kRowsPerChannel)};
  std::vector<std::uint64_t> best_cost(kRowsPerChannel, ~std::uint64_t{0});
  std::vector<std::uint64_t> r;
  for (std::size_t p = 0; p < kPredictors.size(); ++p) {
    r = w;
    difference(&r, 0, kPredictors[p].h);
    difference(&r, 1, kPredictors[p].d);
    difference(&r, 2, kPredictors[p].p);
    for (int row = 0; row < kRowsPerChannel; ++row) {
      const std::size_t base = std::size_t(row) * kPhiDBins;
      std::uint64_t cost = 0;
      for (std::size_t k = base; k < base + kPhiDBins; ++k) {
        if (!is_exception(std::bit_cast<std::uint64_t>(v[k]))) cost += bit_length(zigzag(r[k]));
      }
      if (cost < best_cost[std::size_t(row)]) {
        best_cost[std::size_t(row)] = cost;
        plan.choice[std::size_t(row)] = std::uint8_t(p);
        std::memcpy(plan.residual.data() + base, r.data() + base,
                    kPhiDBins * sizeof(std::uint64_t));
      }
    }
  }
  return plan;
}

// The channel's symbol streams and low-bit stream, written as streams.
std::vector<std::uint8_t> encode_channel(const double* v, const std::vector<std::uint64_t>& res,
                                         int level) {
  std::array<std::vector<std::uint8_t>, kContexts> symbols;
  BitWriter bits;
  std::vector<std::uint8_t> size(kBinsPerChannel, 0);
  for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
    if (is_exception(std::bit_cast<std::uint64_t>(v[i]))) continue;
    const std::uint64_t z = zigzag(res[i]);
    const int len = bit_length(z);
    const int a = i > 0 ? size[i - 1] : 0;
    const int b = i >= kPlaneStride ? size[i - kPlaneStride] : 0;
    if (len < 2) {
      symbols[std::size_t(context_of(a, b))].push_back(std::uint8_t(len));
    } else {
      symbols[std::size_t(context_of(a, b))].push_back(
          std::uint8_t(2 * len - 2 + int((z >> (len - 2)) & 1)));
      bits.put(z & ((std::uint64_t{1} << (len - 2)) - 1), len - 2);
    }
    size[i] = std::uint8_t(len);
  }
  ByteWriter w;
  for (const auto& s : symbols) put_stream(&w, s, level);
  // Low bits are close to noise: a fast level finds what little there is to gain.
  put_stream(&w, bits.finish(), std::min(level, 3));
  return w.take();
}

}  // namespace

std::vector<std::uint8_t> encode_exact_table(const BrdfTable& table, int zstd_level) {
  std::vector<std::uint8_t> bitmap(kBitmapBytes, 0);
  ByteWriter values;
  std::uint32_t count = 0;
  const std::vector<double>& v = table.stored_values();
  for (std::size_t i = 0; i < kTotalBins; ++i) {
    const auto bits = std::bit_cast<std::uint64_t>(v[i]);
    if (!is_exception(bits)) continue;
    bitmap[i >> 3] = std::uint8_t(bitmap[i >> 3] | (1u << (i & 7)));
    values.u64(bits);
    ++count;
  }
  std::vector<std::uint8_t> choices(std::size_t{kChannels} * kRowsPerChannel);
  std::array<std::vector<std::uint8_t>, kChannels> channel_bytes;
  parallel_for(kChannels, 0, [&](int c) {
    const double* data = table.channel_data(c);
    const ChannelPlan plan = plan_channel(working_values(data), data);
    std::memcpy(choices.data() + std::size_t(c) * kRowsPerChannel, plan.choice.data(),
                kRowsPerChannel);
    channel_bytes[std::size_t(c)] = encode_channel(data, plan.residual, zstd_level);
  });
  ByteWriter w;
  w.u8(kMethodPredictive);
  w.u32(count);
  put_stream(&w, bitmap, zstd_level);
  put_stream(&w, values.data(), zstd_level);
  put_stream(&w, choices, zstd_level);
  for (const auto& b : channel_bytes) w.bytes(b);
  return w.take();
}

}  // namespace cbrdf::internal
