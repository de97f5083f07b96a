// SPDX-License-Identifier: MIT
// MASK (spec 4.4): the not-measured mask (exact) and the stored values at its bins. The
// reader (the writer, which chooses the reference and form that make the mask smallest, is the
// encoder's, mask_writer.cc).
#include <xxhash.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <string>

#include "byte_reader.h"
#include "chunks.h"

namespace cbrdf {

const std::vector<std::uint64_t>& below_horizon_bits() {
  // bin_below_horizon for every bin, built on first use, with each axis's sines and cosines
  // computed once instead of five calls per bin: the same calls on the same arguments in the same
  // order give the same bits (tests/decoder/api_validation_test.cc compares every bin).
  static const std::vector<std::uint64_t> bits = [] {
    constexpr double kPi = 3.14159265358979323846, kHalfPi = kPi / 2;
    double sin_h[kThetaHBins], cos_h[kThetaHBins], sin_d[kThetaDBins], cos_d[kThetaDBins];
    double cos_p[kPhiDBins];  // wi's y (the sine's part) does not enter the test
    for (int i = 0; i < kThetaHBins; ++i) {
      const double th = double(i) / kThetaHBins * double(i) / kThetaHBins * kHalfPi;
      sin_h[i] = std::sin(th);
      cos_h[i] = std::cos(th);
    }
    for (int j = 0; j < kThetaDBins; ++j) {
      const double td = double(j) / kThetaDBins * kHalfPi;
      sin_d[j] = std::sin(td);
      cos_d[j] = std::cos(td);
    }
    for (int k = 0; k < kPhiDBins; ++k) {
      const double pd = double(k) / kPhiDBins * kPi;
      cos_p[k] = std::cos(pd);
    }
    std::vector<std::uint64_t> v((kBinsPerChannel + 63) / 64, 0);
    std::size_t i = 0;
    for (int h = 0; h < kThetaHBins; ++h) {
      for (int d = 0; d < kThetaDBins; ++d) {
        for (int p = 0; p < kPhiDBins; ++p, ++i) {
          const double d0 = sin_d[d] * cos_p[p], d2 = cos_d[d];
          const double wi0 = d0 * cos_h[h] + d2 * sin_h[h];
          const double wi2 = -d0 * sin_h[h] + d2 * cos_h[h];
          const double c = wi0 * sin_h[h] + wi2 * cos_h[h];
          const double wo_z = 2 * c * cos_h[h] - wi2;
          if (wi2 <= 0 || wo_z <= 0) v[i >> 6] |= std::uint64_t{1} << (i & 63);
        }
      }
    }
    return v;
  }();
  return bits;
}

std::uint64_t mask_hash(const std::vector<std::uint64_t>& bits) {
  // The hash is of the byte stream (least significant byte of each word first), not of the
  // words, so that its definition does not depend on the host; on a little-endian host the
  // words' memory is that stream.
  static_assert(std::endian::native == std::endian::little);
  return XXH64(bits.data(), kMaskBytes, 0);
}

void xor_below_horizon(std::vector<std::uint64_t>* bits) {
  // Word by word: each channel's copy of the reference starts at a bit offset that is not a
  // multiple of 64, so every word of it is split over two words of the mask.
  const std::vector<std::uint64_t>& g = below_horizon_bits();
  for (int c = 0; c < kChannels; ++c) {
    const std::size_t base = std::size_t(c) * kBinsPerChannel;
    for (std::size_t k = 0; k < g.size(); ++k) {
      const std::size_t at = base + 64 * k, w = at >> 6, shift = at & 63;
      (*bits)[w] ^= g[k] << shift;
      if (shift != 0 && (g[k] >> (64 - shift)) != 0) (*bits)[w + 1] ^= g[k] >> (64 - shift);
    }
  }
}

namespace {

// The fixed fields before the mask: reference, form, values mode, count and hash.
Status read_mask_header(ByteReader& r, MaskFields* fields, std::uint32_t* set_count,
                        std::uint64_t* stored_hash) {
  std::uint8_t reference = 0, form = 0, values = 0, reserved = 0;
  CBRDF_RETURN_IF_ERROR(r.u8(&reference, "mask reference"));
  CBRDF_RETURN_IF_ERROR(r.u8(&form, "mask form"));
  CBRDF_RETURN_IF_ERROR(r.u8(&values, "values mode"));
  CBRDF_RETURN_IF_ERROR(r.u8(&reserved, "reserved byte"));
  CBRDF_RETURN_IF_ERROR(r.u32(set_count, "not-measured count"));
  CBRDF_RETURN_IF_ERROR(r.u64(stored_hash, "mask hash"));
  if (reference > 1 || form > 1 || values > 1 || reserved != 0) {
    return error(ErrorCode::kCorrupt,
                 "mask reference " + std::to_string(reference) + ", form " + std::to_string(form) +
                     ", values mode " + std::to_string(values) + ", reserved " +
                     std::to_string(reserved) + ": each must be 0 or 1 and the reserved byte 0");
  }
  if (*set_count > kMaskBits) {
    return error(ErrorCode::kCorrupt, "not-measured count " + std::to_string(*set_count) +
                                          " exceeds the " + std::to_string(kMaskBits) + " bins");
  }
  fields->reference = MaskReference(reference);
  fields->form = MaskForm(form);
  fields->values = MaskValues(values);
  return ok_status();
}

Status read_mask_bitmap(ByteReader& r, std::vector<std::uint64_t>* bits) {
  std::span<const std::uint8_t> raw;
  CBRDF_RETURN_IF_ERROR(r.bytes(kMaskBytes, &raw, "mask bitmap"));
  for (std::size_t i = 0; i < kMaskBytes; ++i) {
    (*bits)[i >> 3] |= std::uint64_t(raw[i]) << (8 * (i & 7));
  }
  return ok_status();
}

// Alternating runs of clear and set bits, clear first (only the first run may be empty).
Status read_mask_runs(ByteReader& r, std::vector<std::uint64_t>* bits) {
  std::uint32_t runs = 0;
  CBRDF_RETURN_IF_ERROR(r.u32(&runs, "run count"));
  if (runs < 1 || runs > kMaskBits + 1 || runs > r.remaining()) {
    return error(ErrorCode::kCorrupt, "run count " + std::to_string(runs) +
                                          " is not in 1..(bins + 1) or exceeds the " +
                                          std::to_string(r.remaining()) + " bytes left");
  }
  std::size_t pos = 0;
  for (std::uint32_t k = 0; k < runs; ++k) {
    std::uint32_t len = 0;
    const std::uint64_t at = r.offset();
    CBRDF_RETURN_IF_ERROR(r.varint32(&len, "run length"));
    if ((len == 0 && k > 0) || len > kMaskBits - pos) {
      return error(ErrorCode::kCorrupt,
                   "run " + std::to_string(k) + " at payload offset " + std::to_string(at) +
                       " has length " + std::to_string(len) + " (zero, or past the mask's end)");
    }
    if (k % 2 == 1) {  // odd runs are set bits
      for (std::size_t b = pos; b < pos + len; ++b) (*bits)[b >> 6] |= std::uint64_t{1} << (b & 63);
    }
    pos += len;
  }
  if (pos != kMaskBits) {
    return error(ErrorCode::kCorrupt, "runs cover " + std::to_string(pos) + " of the " +
                                          std::to_string(kMaskBits) + " mask bits");
  }
  return ok_status();
}

// The rebuilt mask against its declared count and hash; returns the count.
Expected<std::size_t> check_mask(const std::vector<std::uint64_t>& bits, std::uint32_t set_count,
                                 std::uint64_t stored_hash, MaskReference reference) {
  const std::size_t count = count_set_bits(bits);
  if (count != set_count) {
    return error(ErrorCode::kCorrupt, "the mask has " + std::to_string(count) +
                                          " not-measured bins but declares " +
                                          std::to_string(set_count));
  }
  const std::uint64_t h = mask_hash(bits);
  if (h != stored_hash) {
    return error(ErrorCode::kChecksum,
                 "the reconstructed mask does not match its hash (reference " +
                     std::to_string(int(reference)) +
                     "; a reader whose below-horizon geometry differs from the spec's would "
                     "see this)");
  }
  return count;
}

// The stored values at the not-measured bins: n_values doubles, each negative.
Status read_not_measured_values(ByteReader& r, std::size_t n_values, std::vector<double>* values) {
  const std::uint64_t values_at = r.offset();
  std::span<const std::uint8_t> raw;
  CBRDF_RETURN_IF_ERROR(r.bytes(n_values * 8, &raw, "not-measured values"));
  // One bounds check, then one copy: a checked read per value made the 4.4 million values of the
  // largest file cost seconds under the sanitizers (a fuzzer timeout). Little-endian hosts only.
  static_assert(std::endian::native == std::endian::little);
  values->resize(n_values);
  std::memcpy(values->data(), raw.data(), raw.size());
  for (std::size_t k = 0; k < n_values; ++k) {
    if ((*values)[k] >= 0.0) {
      return error(ErrorCode::kNumeric, "not-measured value " + number_text((*values)[k]) +
                                            " at payload offset " +
                                            std::to_string(values_at + 8 * k) +
                                            " is not negative (it would read as measured)");
    }
  }
  return ok_status();
}

}  // namespace

Status decode_mask_chunk(std::span<const std::uint8_t> payload, std::uint16_t file_minor,
                         NotMeasured* out, MaskFields* fields) {
  ByteReader r(payload, 0, "payload offset");
  std::uint32_t set_count = 0;
  std::uint64_t stored_hash = 0;
  CBRDF_RETURN_IF_ERROR(read_mask_header(r, fields, &set_count, &stored_hash));
  out->bits.assign((kMaskBits + 63) / 64, 0);
  if (fields->form == MaskForm::kBitmap) {
    CBRDF_RETURN_IF_ERROR(read_mask_bitmap(r, &out->bits));
  } else {
    CBRDF_RETURN_IF_ERROR(read_mask_runs(r, &out->bits));
  }
  if (fields->reference == MaskReference::kBelowHorizon) xor_below_horizon(&out->bits);
  CBRDF_ASSIGN_OR_RETURN(std::size_t count,
                         check_mask(out->bits, set_count, stored_hash, fields->reference));
  const std::size_t n_values = fields->values == MaskValues::kSingle ? 1 : count;
  CBRDF_RETURN_IF_ERROR(read_not_measured_values(r, n_values, &out->values));
  return check_trailing(r.remaining(), file_minor);
}

}  // namespace cbrdf
