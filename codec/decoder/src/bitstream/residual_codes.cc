// SPDX-License-Identifier: MIT
#include "residual_codes.h"

#include <array>
#include <bit>
#include <memory>
#include <string>

#include "chunks.h"
#include "range_coder.h"
#include "residual_code_contexts.h"

namespace cbrdf::internal {

using namespace residual_contexts;

namespace {

constexpr std::array<std::uint8_t, kPhiDBins> make_iota() {
  std::array<std::uint8_t, kPhiDBins> t{};
  for (int p = 0; p < kPhiDBins; ++p) t[std::size_t(p)] = std::uint8_t(p);
  return t;
}
constexpr std::array<std::uint8_t, kPhiDBins> kAllBins = make_iota();

}  // namespace

std::span<const std::uint8_t> measured_bins(const NotMeasured& mask, std::size_t b0,
                                            std::array<std::uint8_t, kPhiDBins>& list) {
  std::array<std::uint64_t, 3> w{};
  const std::size_t word = b0 >> 6, shift = b0 & 63;
  const std::size_t words = mask.bits.size();
  for (std::size_t j = 0; j < 3; ++j) {
    const std::uint64_t lo = word + j < words ? mask.bits[word + j] : ~std::uint64_t{0};
    const std::uint64_t hi = shift != 0 && word + j + 1 < words ? mask.bits[word + j + 1] : 0;
    w[j] = shift != 0 ? (lo >> shift) | (hi << (64 - shift)) : lo;  // not-measured bits
  }
  constexpr std::uint64_t kLast = (std::uint64_t{1} << (kPhiDBins - 128)) - 1;
  w[2] &= kLast;
  if ((w[0] | w[1] | w[2]) == 0) return kAllBins;
  std::size_t n = 0;
  for (std::size_t j = 0; j < 3; ++j) {
    for (std::uint64_t m = ~w[j] & (j == 2 ? kLast : ~std::uint64_t{0}); m != 0; m &= m - 1) {
      list[n++] = std::uint8_t(64 * j + std::size_t(std::countr_zero(m)));
    }
  }
  return {list.data(), n};
}

Status decode_residual_codes(std::span<const std::uint8_t> in, std::uint64_t at,
                             const NotMeasured& mask, std::int32_t* q) {
  auto m = std::make_unique<CodeModel>();
  internal::Decoder dec(in);
  Coded coded;
  Status bad = ok_status();
  // The bin of a code that fails, for the message.
  const auto refuse = [&](const Row& row, std::size_t p, const std::string& what) {
    bad = error(ErrorCode::kCorrupt,
                std::string("the range-coded code of channel ") + kChannelNames[row.c] + " bin " +
                    std::to_string(row.i0 + p) + " (stream at payload offset " +
                    std::to_string(at) + ") " + what);
    return false;
  };
  const bool read = for_each_row(q, mask, coded, [&](const Row& row) {
    bool row_nonzero = false;
    for (const std::size_t p : row.bins) {
      const std::size_t k = std::size_t(row.k[p]);
      if (dec.bit(m->zero[k]) == 0) continue;  // q is zero-filled
      Contexts& cx = m->ctx[k];
      const int negative = dec.bit(m->sign[std::size_t(row.signs.context(p))]);
      int n = 0;
      while (n <= kMaxCodeExponent && dec.bit(cx.exponent[std::size_t(n)]) != 0) ++n;
      if (n > kMaxCodeExponent) {
        return refuse(row, p, "has an exponent above " + std::to_string(kMaxCodeExponent));
      }
      std::uint32_t x = 1;
      for (int j = n - 1; j >= 0; --j) {
        x = (x << 1) | std::uint32_t(dec.bit(cx.mantissa[std::size_t(n)][std::size_t(j)]));
      }
      if (x > std::uint32_t(kMaxResidualCode)) return refuse(row, p, "is outside -2^28..2^28");
      q[row.b0 + p] = negative ? -std::int32_t(x) : std::int32_t(x);
      coded.magnitude[row.b0 + p] = capped_magnitude(q[row.b0 + p]);
      row_nonzero = true;
    }
    coded.nonzero[row.b0 / kPhiDBins] = row_nonzero ? 1 : 0;
    return true;
  });
  if (!read) return bad;
  Status s = dec.finish();
  if (!s.ok()) {
    return s.with_context("range-coded codes at payload offset " + std::to_string(at));
  }
  return ok_status();
}

}  // namespace cbrdf::internal
