// SPDX-License-Identifier: MIT
// RESD (spec 4.6): the error-bounded residual layer of container 1.2. The reader (the writer is
// the encoder's, resd_writer.cc).
//
// Modes 0 and 2 hold one integer code per measured bin (channel, then MERL index order), each
// coded as the zigzag of its difference from a prediction out of codes already decoded, as an
// unsigned LEB128 varint; the chunk's zstd frame does the entropy coding. Mode 2 adds one step
// shift per (theta_h, theta_d) row before the codes; mode 3 adds the level count and the finest
// level's multiplier after them, and its codes correct an interpolation (residual_levels.h); mode
// 4 (version 1.3) adds a multiplier for each level between the finest and the coarsest.
// In version 1.3 the codes may instead be range coded with contexts (residual_codes.h), either
// as they are or after a prediction across slabs and channels (residual_prediction.h).
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <string>

#include "byte_reader.h"
#include "chunks.h"
#include "exact_table.h"
#include "residual_codes.h"
#include "residual_levels.h"
#include "residual_prediction.h"

namespace cbrdf {
namespace {

Status check_header(std::uint8_t predictor, std::uint16_t reserved, double max_error, double step,
                    double knee, std::uint32_t escapes, std::uint16_t file_minor) {
  const std::uint8_t top =
      file_minor >= 3 ? kResidualPredictorRangePredicted : kResidualPredictorPhi;
  if (predictor > top || reserved != 0) {
    return error(ErrorCode::kCorrupt,
                 "predictor " + std::to_string(predictor) + " / reserved " +
                     std::to_string(reserved) +
                     ": the predictor must be 0 or 1 (2, range-coded codes, and 3, range-coded " +
                     "codes after prediction, from version 1.3 on) and the reserved field 0");
  }
  if (!(max_error >= kMinResidualError && max_error <= kMaxResidualError)) {
    return error(ErrorCode::kNumeric, "max error " + number_text(max_error) + " is outside " +
                                          number_text(kMinResidualError) + ".." +
                                          number_text(kMaxResidualError));
  }
  if (!(step > 0.0 && step <= 2.0 * max_error)) {
    return error(ErrorCode::kNumeric,
                 "step " + number_text(step) + " is not in (0, 2 x max error]");
  }
  if (!(knee >= kMinResidualKnee && knee <= kMaxResidualKnee)) {
    return error(ErrorCode::kNumeric, "knee " + number_text(knee) + " is outside " +
                                          number_text(kMinResidualKnee) + ".." +
                                          number_text(kMaxResidualKnee));
  }
  if (escapes > kMaxResidualEscapes) {
    return error(ErrorCode::kLimit, "escape count " + std::to_string(escapes) + " exceeds " +
                                        std::to_string(kMaxResidualEscapes));
  }
  return ok_status();
}

// The codes of the measured bins, read straight from the payload (a checked read per varint
// made the largest payloads slow under the sanitizers). Returns the bytes consumed.
Expected<std::size_t> read_codes(std::span<const std::uint8_t> in, std::size_t base,
                                 const NotMeasured& mask, std::uint8_t predictor, std::int32_t* q) {
  std::size_t pos = 0;
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (mask.test(c, i)) continue;
      std::uint64_t z = 0;
      const std::size_t start = pos;
      for (int k = 0;; ++k) {
        if (pos == in.size()) {
          return error(ErrorCode::kTruncated, "the codes end at payload offset " +
                                                  std::to_string(base + pos) +
                                                  " before the last measured bin");
        }
        const std::uint8_t b = in[pos++];
        z |= std::uint64_t(b & 0x7F) << (7 * k);
        if ((b & 0x80) == 0) {
          if ((k > 0 && b == 0) || z > 0xFFFFFFFFu || k >= 5) {
            return error(ErrorCode::kCorrupt, "code varint at payload offset " +
                                                  std::to_string(base + start) +
                                                  " is overlong or exceeds 2^32-1");
          }
          break;
        }
        if (k == 4) {
          return error(ErrorCode::kCorrupt, "code varint at payload offset " +
                                                std::to_string(base + start) +
                                                " is longer than 5 bytes");
        }
      }
      const std::int64_t code =
          varint_code_prediction(q, c, i, predictor) + unzigzag(std::uint32_t(z));
      if (code < -kMaxResidualCode || code > kMaxResidualCode) {
        return error(ErrorCode::kCorrupt, "code " + std::to_string(code) + " of channel " +
                                              kChannelNames[c] + " bin " + std::to_string(i) +
                                              " (payload offset " + std::to_string(base + start) +
                                              ") is outside -2^28..2^28");
      }
      q[std::size_t(c) * kBinsPerChannel + i] = std::int32_t(code);
    }
  }
  return pos;
}

Status read_escapes(ByteReader& r, std::uint32_t count, const NotMeasured& mask,
                    std::vector<ResidualEscape>* out) {
  out->resize(count);
  std::uint64_t next = 0;  // the smallest bin the next escape may name
  for (ResidualEscape& e : *out) {
    std::uint32_t gap = 0;
    const std::uint64_t at = r.offset();
    CBRDF_RETURN_IF_ERROR(r.varint32(&gap, "escape gap"));
    CBRDF_RETURN_IF_ERROR(r.f64(&e.stored, "escape value"));
    const std::uint64_t bin = next + gap;
    if (bin >= kMaskBits || mask_bit(mask.bits, std::size_t(bin))) {
      return error(ErrorCode::kCorrupt, "escape at payload offset " + std::to_string(at) +
                                            " names bin " + std::to_string(bin) +
                                            ", which is past the table or not measured");
    }
    if (!std::isfinite(e.stored) || e.stored < 0.0) {
      return error(ErrorCode::kNumeric, "escape value " + number_text(e.stored) +
                                            " at payload offset " + std::to_string(at) +
                                            " is not a finite value >= 0");
    }
    e.bin = std::uint32_t(bin);
    next = bin + 1;
  }
  return ok_status();
}

// Mode 2's row shifts: each at most kMaxResidualShift, and no row's bound above the format's.
Status read_row_shifts(ByteReader& r, Residual* out) {
  std::span<const std::uint8_t> shifts;
  const std::uint64_t at = r.offset();
  CBRDF_RETURN_IF_ERROR(r.bytes(kResidualRows, &shifts, "row shifts"));
  for (std::size_t row = 0; row < kResidualRows; ++row) {
    const int s = shifts[row];
    if (s > kMaxResidualShift || std::ldexp(out->max_error, s) > kMaxResidualError) {
      return error(ErrorCode::kNumeric,
                   "row shift " + std::to_string(s) + " at payload offset " +
                       std::to_string(at + row) + " exceeds " +
                       std::to_string(int(kMaxResidualShift)) +
                       " or makes the row's bound (max error x 2^shift) exceed " +
                       number_text(kMaxResidualError));
    }
  }
  out->row_shift.assign(shifts.begin(), shifts.end());
  return ok_status();
}

// Modes 3 and 4: the level count and the finest level's multiplier after the row shifts; in mode
// 4 then one multiplier per level between the finest and the coarsest, finer first.
Status read_levels(ByteReader& r, bool middle, Residual* out) {
  const std::uint64_t at = r.offset();
  CBRDF_RETURN_IF_ERROR(r.u8(&out->levels, "level count"));
  CBRDF_RETURN_IF_ERROR(r.u8(&out->fine_multiplier, "finest level's multiplier"));
  if (out->levels < 1 || out->levels > kMaxResidualLevels || (middle && out->levels < 2)) {
    return error(ErrorCode::kCorrupt, "level count " + std::to_string(int(out->levels)) +
                                          " at payload offset " + std::to_string(at) +
                                          " is not in " + (middle ? "2.." : "1..") +
                                          std::to_string(kMaxResidualLevels));
  }
  out->middle_multipliers = {1, 1, 1};
  for (int l = 1; middle && l < out->levels; ++l) {
    CBRDF_RETURN_IF_ERROR(
        r.u8(&out->middle_multipliers[std::size_t(l - 1)], "a middle level's multiplier"));
  }
  if (const int l = internal::level_multiplier_out_of_range(*out); l >= 0) {
    return error(ErrorCode::kNumeric,
                 (l == 0 ? std::string("finest level's") : "level " + std::to_string(l) + "'s") +
                     " multiplier " + std::to_string(out->multiplier_of_level(l)) +
                     " at payload offset " + std::to_string(at + 1 + std::uint64_t(l)) +
                     " is not in 1.." + std::to_string(kMaxFineMultiplier) +
                     " or makes a bound (multiplier x max error x 2^shift) exceed " +
                     number_text(kMaxResidualError));
  }
  return ok_status();
}

// Every bin's residual within +-kMaxResidualValue (mode 3: every rebuilt value, not-measured bins
// included, as they feed predictions and continuous evaluation).
Status check_residual_values(const Residual& r, std::uint64_t codes_at) {
  for (std::size_t b = 0; b < kMaskBits; ++b) {
    const double v = r.value_at(b);
    if (!(std::abs(v) <= kMaxResidualValue)) {
      const std::size_t i = b % kBinsPerChannel;
      return error(ErrorCode::kNumeric,
                   std::string("the residual of channel ") + kChannelNames[b / kBinsPerChannel] +
                       " bin " + std::to_string(i) + " is " + number_text(v) +
                       (r.interpolated() ? " (rebuilt level by level)" : " (code x step)") +
                       ", beyond +-" + number_text(kMaxResidualValue) +
                       " (codes from payload offset " + std::to_string(codes_at) + ")");
    }
  }
  return ok_status();
}

// Mode 1: the exact table, whose not-measured bins must be MASK's.
Status read_exact(std::span<const std::uint8_t> rest, const NotMeasured& mask, Residual* out) {
  Expected<BrdfTable> t = internal::decode_exact_table(rest);
  if (!t.ok()) {
    // Most of the table coder's messages name it already; prefix only those that do not.
    const bool named = t.status().message().rfind("exact table", 0) == 0;
    return named ? t.status() : t.status().with_context("exact table");
  }
  for (int c = 0; c < kChannels; ++c) {
    const double* v = t->channel_data(c);
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (!(v[i] >= 0.0) != mask.test(c, i)) {
        return error(ErrorCode::kCorrupt, std::string("exact table: channel ") + kChannelNames[c] +
                                              " bin " + std::to_string(i) + " is " +
                                              (mask.test(c, i) ? "" : "not ") +
                                              "measured, MASK says the opposite");
      }
    }
  }
  out->exact = std::make_shared<const BrdfTable>(std::move(t).value());
  return ok_status();
}

}  // namespace

Status decode_residual_chunk(std::span<const std::uint8_t> payload, std::uint16_t file_minor,
                             const NotMeasured& mask, Residual* out, std::uint8_t* predictor_out) {
  ByteReader r = payload_reader(payload);
  std::uint8_t mode = 0, predictor = 0;
  std::uint16_t reserved = 0;
  std::uint32_t escapes = 0;
  CBRDF_RETURN_IF_ERROR(r.u8(&mode, "residual mode"));
  if (mode == kResidualModeExact) return read_exact(payload.subspan(1), mask, out);
  if (mode != kResidualModeLog && mode != kResidualModeRows && mode != kResidualModeInterp &&
      mode != kResidualModeLevelSteps) {
    return error(ErrorCode::kUnsupported,
                 "residual mode " + std::to_string(mode) +
                     " is not known to this reader (0 = bounded log residual, 1 = exact table, "
                     "2 = a step per row, 3 = interpolated levels, 4 = a step per level)");
  }
  if (mode == kResidualModeLevelSteps && file_minor < 3) {
    return error(ErrorCode::kCorrupt, "residual mode 4 (a step per level) in a version 1." +
                                          std::to_string(file_minor) +
                                          " file: it exists from version 1.3 on");
  }
  CBRDF_RETURN_IF_ERROR(r.u8(&predictor, "predictor"));
  CBRDF_RETURN_IF_ERROR(r.u16(&reserved, "reserved field"));
  CBRDF_RETURN_IF_ERROR(r.f64(&out->max_error, "max error"));
  CBRDF_RETURN_IF_ERROR(r.f64(&out->step, "step"));
  CBRDF_RETURN_IF_ERROR(r.f64(&out->knee, "knee"));
  CBRDF_RETURN_IF_ERROR(r.u32(&escapes, "escape count"));
  CBRDF_RETURN_IF_ERROR(
      check_header(predictor, reserved, out->max_error, out->step, out->knee, escapes, file_minor));
  if (predictor_out != nullptr) *predictor_out = predictor;
  out->row_shift.clear();
  out->levels = 0;
  out->fine_multiplier = 1;
  out->middle_multipliers = {1, 1, 1};
  out->values.clear();
  if (mode != kResidualModeLog) CBRDF_RETURN_IF_ERROR(read_row_shifts(r, out));
  if (mode == kResidualModeInterp || mode == kResidualModeLevelSteps) {
    CBRDF_RETURN_IF_ERROR(read_levels(r, mode == kResidualModeLevelSteps, out));
  }
  out->codes.assign(kMaskBits, 0);
  std::span<const std::uint8_t> rest;
  std::uint64_t codes_at = r.offset();
  if (predictor == kResidualPredictorRange || predictor == kResidualPredictorRangePredicted) {
    internal::CodePrediction prediction;
    if (predictor == kResidualPredictorRangePredicted) {
      CBRDF_RETURN_IF_ERROR(
          internal::read_prediction(r, internal::prediction_groups(*out), &prediction));
    }
    std::uint32_t length = 0;
    CBRDF_RETURN_IF_ERROR(r.u32(&length, "coded stream length"));
    codes_at = r.offset();
    CBRDF_RETURN_IF_ERROR(r.bytes(length, &rest, "coded stream"));
    CBRDF_RETURN_IF_ERROR(internal::decode_residual_codes(rest, codes_at, mask, out->codes.data()));
    if (predictor == kResidualPredictorRangePredicted) {
      CBRDF_RETURN_IF_ERROR(
          internal::unpredict_codes(out->codes.data(), mask, *out, prediction, codes_at));
    }
    CBRDF_RETURN_IF_ERROR(read_escapes(r, escapes, mask, &out->escapes));
    CBRDF_RETURN_IF_ERROR(check_trailing(r.remaining(), file_minor));
  } else {
    CBRDF_RETURN_IF_ERROR(r.bytes(r.remaining(), &rest, "codes"));
    CBRDF_ASSIGN_OR_RETURN(std::size_t used,
                           read_codes(rest, codes_at, mask, predictor, out->codes.data()));
    ByteReader tail(rest.subspan(used), codes_at + used, "payload offset");
    CBRDF_RETURN_IF_ERROR(read_escapes(tail, escapes, mask, &out->escapes));
    CBRDF_RETURN_IF_ERROR(check_trailing(tail.remaining(), file_minor));
  }
  if (out->interpolated()) internal::rebuild_interpolated(out);
  return check_residual_values(*out, codes_at);
}

}  // namespace cbrdf
