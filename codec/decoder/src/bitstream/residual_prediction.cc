// SPDX-License-Identifier: MIT
#include "residual_prediction.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "byte_reader.h"
#include "chunks.h"
#include "residual_codes.h"

namespace cbrdf::internal {
namespace {

constexpr std::size_t kSlab = std::size_t(kThetaDBins) * kPhiDBins;
constexpr int kFeatures = 3;  // U, X and XU

}  // namespace

int row_shift_of(const Residual& res, std::size_t row) {
  return res.row_shift.empty() ? 0 : int(res.row_shift[row]);
}

std::vector<std::uint8_t> group_table(const Residual& res) {
  std::vector<std::uint8_t> g(kSlab, 0);
  if (!res.interpolated()) return g;
  for (std::size_t i = 0; i < kSlab; ++i) g[i] = std::uint8_t(res.level_of(i));
  return g;
}

bool CodePrediction::any() const {
  for (const auto& k : coef) {
    if (k[0] != 0 || k[1] != 0 || k[2] != 0) return true;
  }
  return false;
}

int prediction_groups(const Residual& residual) {
  return residual.interpolated() ? residual.levels + 1 : 1;
}

Status read_prediction(ByteReader& r, int groups, CodePrediction* out) {
  out->groups = groups;
  out->coef.assign(std::size_t(kChannels * groups), {0, 0, 0});
  for (int c = 0; c < kChannels; ++c) {
    for (int g = 0; g < groups; ++g) {
      auto& k = out->at(c, g);
      for (int j = 0; j < (c == 0 ? 1 : kFeatures); ++j) {
        std::uint16_t v = 0;
        CBRDF_RETURN_IF_ERROR(r.u16(&v, "a prediction coefficient"));
        k[std::size_t(j)] = std::int16_t(v);
      }
    }
  }
  return ok_status();
}

namespace {

// The end of a rebuilt row (v: the codes of its 180 bins, 32- or 64-bit): refused if a measured
// bin's code leaves -2^28..2^28, else stored at the measured bins (not-measured bins keep 0: the
// stream left them 0 and they are never predicted).
template <class T>
Status store_row(const T* v, const NotMeasured& mask, std::size_t b0, std::int32_t* out,
                 std::uint64_t at) {
  T lo = 0, hi = 0;
  for (std::size_t p = 0; p < kPhiDBins; ++p) {
    lo = std::min(lo, v[p]);
    hi = std::max(hi, v[p]);
  }
  std::array<std::uint8_t, kPhiDBins> list;
  const std::span<const std::uint8_t> bins = measured_bins(mask, b0, list);
  if (lo < -kMaxResidualCode || hi > kMaxResidualCode) {
    for (const std::size_t p : bins) {
      if (v[p] >= -kMaxResidualCode && v[p] <= kMaxResidualCode) continue;
      return error(
          ErrorCode::kCorrupt,
          "the predicted code of channel " + std::string(kChannelNames[b0 / kBinsPerChannel]) +
              " bin " + std::to_string(b0 % kBinsPerChannel + p) + " is " + std::to_string(v[p]) +
              ", outside -2^28..2^28 (stream at payload offset " + std::to_string(at) + ")");
    }
  }
  if (bins.size() == kPhiDBins) {
    for (std::size_t p = 0; p < kPhiDBins; ++p) out[p] = std::int32_t(v[p]);
  } else {
    for (const std::size_t p : bins) out[p] = std::int32_t(v[p]);
  }
  return ok_status();
}

// One row of P + r in type T (int32_t where every term fits, else int64_t): each neighbour times
// 2^delta (delta >= 0, as a product: a left shift of a negative value is what sanitizers flag)
// or shifted right by -delta (an arithmetic shift: floor division).
template <class T>
void predict_row(const std::int32_t* r, const std::int32_t* up, const std::int32_t* x,
                 const std::int32_t* xu, const T* a, const T* b, const T* g, int delta, T* v) {
  if (delta >= 0) {
    const T m = T(1) << delta;
    for (std::size_t p = 0; p < kPhiDBins; ++p) {
      v[p] = r[p] + ((a[p] * (T(up[p]) * m) + b[p] * T(x[p]) + g[p] * (T(xu[p]) * m) + 128) >> 8);
    }
  } else {
    const int s = -delta;
    for (std::size_t p = 0; p < kPhiDBins; ++p) {
      v[p] = r[p] + ((a[p] * (T(up[p]) >> s) + b[p] * T(x[p]) + g[p] * (T(xu[p]) >> s) + 128) >> 8);
    }
  }
}

// What a row's neighbours need: nothing when they are all 0 (P = 0: the codes are the stream's,
// as at coarse bounds in most rows), 32 bits when all are at most 2^14 in magnitude, up and xu
// once scaled by 2^delta (every term of P is then below 2^29 with |coefficient| <= 2^15, and
// P + r fits), else 64 bits.
enum class RowWidth { kZero, k32, k64 };
RowWidth row_width(const std::int32_t* up, const std::int32_t* x, const std::int32_t* xu,
                   int delta) {
  std::uint32_t scaled_bits = 0, bits = 0, any = 0;
  for (std::size_t p = 0; p < kPhiDBins; ++p) {
    // v XOR its sign is |v| for v >= 0 and |v| - 1 below: under 2^14 exactly when |v| <= 2^14.
    scaled_bits |= std::uint32_t(up[p] ^ (up[p] >> 31)) | std::uint32_t(xu[p] ^ (xu[p] >> 31));
    bits |= std::uint32_t(x[p] ^ (x[p] >> 31));
    any |= std::uint32_t(up[p]) | std::uint32_t(x[p]) | std::uint32_t(xu[p]);
  }
  const int left = delta > 0 ? delta : 0;
  if (any == 0) return RowWidth::kZero;
  return bits < (1u << 14) && scaled_bits < (1u << (14 - left)) ? RowWidth::k32 : RowWidth::k64;
}

}  // namespace

Status unpredict_codes(std::int32_t* q, const NotMeasured& mask, const Residual& residual,
                       const CodePrediction& p, std::uint64_t at) {
  // The decoder's loop, a row of 180 bins at a time so that it vectorizes: each coefficient laid
  // out along the row for the 16 patterns of theta_d mod 16 (a level is min(tz(d), tz(p), L),
  // L <= 4), one scale per row, 32-bit arithmetic where the row's values allow (64-bit multiplies
  // do not vectorize on baseline x86-64), and the mask read only for rows that hold a
  // not-measured bin. The writer's per-bin loop (predict_codes) is the reference it must equal.
  constexpr int kPatterns = 16;
  const std::vector<std::uint8_t> group = group_table(residual);
  const std::size_t per_channel = std::size_t(kPatterns) * 3 * kPhiDBins;
  std::vector<std::int32_t> coef32(std::size_t(kChannels) * per_channel);
  std::vector<std::int64_t> coef64(coef32.size());
  for (int c = 0; c < kChannels; ++c) {
    for (int d = 0; d < kPatterns; ++d) {
      for (int j = 0; j < 3; ++j) {
        const std::size_t at_row =
            std::size_t(c) * per_channel + (std::size_t(d) * 3 + std::size_t(j)) * kPhiDBins;
        for (std::size_t ph = 0; ph < kPhiDBins; ++ph) {
          coef32[at_row + ph] = p.at(c, group[std::size_t(d) * kPhiDBins + ph])[std::size_t(j)];
          coef64[at_row + ph] = coef32[at_row + ph];
        }
      }
    }
  }
  static constexpr std::int32_t kZeros[kPhiDBins] = {};
  for (int c = 0; c < kChannels; ++c) {
    const std::size_t cb = std::size_t(c) * kBinsPerChannel;
    for (int h = 0; h < kThetaHBins; ++h) {
      for (int d = 0; d < kThetaDBins; ++d) {
        const std::size_t row = std::size_t(h) * kThetaDBins + std::size_t(d);
        const std::size_t b0 = cb + row * kPhiDBins;
        int delta = h > 0 ? row_shift_of(residual, row - kThetaDBins) - row_shift_of(residual, row)
                          : kPredictionShiftLimit + 1;
        const bool drop = delta > kPredictionShiftLimit || delta < -kPredictionShiftLimit;
        if (drop) delta = 0;  // the slab before contributes nothing: its rows read as zeros
        const std::int32_t* up = h > 0 && !drop ? q + b0 - kSlab : kZeros;
        const std::int32_t* x = c > 0 ? q + b0 - kBinsPerChannel : kZeros;
        const std::int32_t* xu =
            c > 0 && h > 0 && !drop ? q + b0 - kBinsPerChannel - kSlab : kZeros;
        const std::size_t k =
            std::size_t(c) * per_channel + std::size_t(d % kPatterns) * 3 * kPhiDBins;
        const RowWidth width = row_width(up, x, xu, delta);
        if (width == RowWidth::kZero) continue;
        if (width == RowWidth::k32) {
          std::int32_t v[kPhiDBins];
          const std::int32_t* cf = coef32.data() + k;
          predict_row(q + b0, up, x, xu, cf, cf + kPhiDBins, cf + 2 * kPhiDBins, delta, v);
          CBRDF_RETURN_IF_ERROR(store_row(v, mask, b0, q + b0, at));
        } else {
          std::int64_t v[kPhiDBins];
          const std::int64_t* cf = coef64.data() + k;
          predict_row(q + b0, up, x, xu, cf, cf + kPhiDBins, cf + 2 * kPhiDBins, delta, v);
          CBRDF_RETURN_IF_ERROR(store_row(v, mask, b0, q + b0, at));
        }
      }
    }
  }
  return ok_status();
}

}  // namespace cbrdf::internal
