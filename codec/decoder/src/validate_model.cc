// SPDX-License-Identifier: MIT
// validate_model: what a container can hold (spec/container.md section 4), the one check of
// encode_model's input and of every decoded model (the fuzz targets' invariant).
#include <bit>
#include <cmath>
#include <string>

#include "bitstream/chunks.h"
#include "bitstream/residual_levels.h"
#include "cbrdf/model.h"

namespace cbrdf {
namespace {

Status invalid(std::string message) {
  return error(ErrorCode::kInvalidArgument, std::move(message));
}

Status check_table(const std::vector<double>& t, std::size_t size, const std::string& what) {
  if (t.size() != size) {
    return invalid(what + " has " + std::to_string(t.size()) + " values, expected " +
                   std::to_string(size));
  }
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (!std::isfinite(t[i]) || t[i] < 0.0) {
      return invalid(what + " value " + std::to_string(i) + " is " + number_text(t[i]) +
                     " (masses must be finite and >= 0)");
    }
  }
  return ok_status();
}

// The residual against what RESD can hold (spec 4.6).
Status check_residual(const Model& model) {
  const Residual& r = model.residual;
  if (!r.present()) return ok_status();
  if (r.exact) {
    for (std::size_t b = 0; b < kMaskBits; ++b) {
      if (!(r.exact->stored_values()[b] >= 0.0) != mask_bit(model.not_measured.bits, b)) {
        return invalid("the exact table's not-measured bins differ from the model's mask at bin " +
                       std::to_string(b));
      }
    }
    return ok_status();
  }
  if (!(r.max_error >= kMinResidualError && r.max_error <= kMaxResidualError)) {
    return invalid("residual max error " + number_text(r.max_error) + " is outside " +
                   number_text(kMinResidualError) + ".." + number_text(kMaxResidualError));
  }
  if (!(r.step > 0.0 && r.step <= 2.0 * r.max_error)) {
    return invalid("residual step " + number_text(r.step) + " is not in (0, 2 x max error]");
  }
  if (!(r.knee >= kMinResidualKnee && r.knee <= kMaxResidualKnee)) {
    return invalid("residual knee " + number_text(r.knee) + " is outside " +
                   number_text(kMinResidualKnee) + ".." + number_text(kMaxResidualKnee));
  }
  if (!r.row_shift.empty()) {
    const int top = r.max_row_shift();
    if (r.row_shift.size() != kResidualRows || top > kMaxResidualShift ||
        std::ldexp(r.max_error, top) > kMaxResidualError) {
      return invalid("the residual's row shifts (" + std::to_string(r.row_shift.size()) +
                     ", largest " + std::to_string(int(top)) + ") are not " +
                     std::to_string(kResidualRows) + " values of at most " +
                     std::to_string(int(kMaxResidualShift)) + " with max error x 2^shift <= 16");
    }
  }
  if (r.interpolated()) {
    if (r.levels > kMaxResidualLevels || r.row_shift.size() != kResidualRows ||
        internal::level_multiplier_out_of_range(r) >= 0 || r.values.size() != kMaskBits) {
      return invalid("the interpolated residual needs 1.." + std::to_string(kMaxResidualLevels) +
                     " levels, " + std::to_string(kResidualRows) +
                     " row shifts, level multipliers of 1.." + std::to_string(kMaxFineMultiplier) +
                     " within the bound limit 16, and its rebuilt values");
    }
  }
  if (r.codes.size() != kMaskBits) {
    return invalid("the residual has " + std::to_string(r.codes.size()) + " codes, expected " +
                   std::to_string(kMaskBits));
  }
  for (std::size_t b = 0; b < kMaskBits; ++b) {
    const bool masked = mask_bit(model.not_measured.bits, b);
    if ((masked && r.codes[b] != 0) || r.codes[b] < -kMaxResidualCode ||
        r.codes[b] > kMaxResidualCode) {
      return invalid("residual code " + std::to_string(r.codes[b]) + " at bin " +
                     std::to_string(b) + " is outside -2^28..2^28 or at a not-measured bin");
    }
  }
  if (r.interpolated() || r.codes.size() == kMaskBits) {
    for (std::size_t b = 0; b < kMaskBits; ++b) {
      if (!(std::abs(r.value_at(b)) <= kMaxResidualValue)) {
        return invalid("the residual at bin " + std::to_string(b) + " is " +
                       number_text(r.value_at(b)) + ", beyond the format's +-" +
                       number_text(kMaxResidualValue));
      }
    }
  }
  if (r.escapes.size() > kMaxResidualEscapes) {
    return invalid(std::to_string(r.escapes.size()) + " residual escapes; at most " +
                   std::to_string(kMaxResidualEscapes) + " fit in a file");
  }
  std::int64_t prev = -1;
  for (const ResidualEscape& e : r.escapes) {
    if (std::int64_t(e.bin) <= prev || e.bin >= kMaskBits ||
        mask_bit(model.not_measured.bits, e.bin) || !std::isfinite(e.stored) || e.stored < 0.0) {
      return invalid("residual escape at bin " + std::to_string(e.bin) +
                     " is out of order, at a not-measured bin or not a finite value >= 0");
    }
    prev = e.bin;
  }
  return ok_status();
}

}  // namespace

Status validate_model(const Model& model) {
  if (model.slices.empty() || model.slices.size() > std::size_t{kThetaDBins}) {
    return invalid("the model has " + std::to_string(model.slices.size()) +
                   " slices, expected 1..90");
  }
  int begin = 0;
  for (std::size_t s = 0; s < model.slices.size(); ++s) {
    const Slice& slice = model.slices[s];
    const std::string name = "slice " + std::to_string(s);
    if (slice.theta_d_begin != begin || slice.theta_d_end <= begin ||
        slice.theta_d_end > kThetaDBins) {
      return invalid(name + " covers theta_d bins [" + std::to_string(slice.theta_d_begin) + ", " +
                     std::to_string(slice.theta_d_end) +
                     "); slices must be non-empty and "
                     "contiguous from 0");
    }
    begin = slice.theta_d_end;
    for (std::size_t c = 0; c < kChannels; ++c) {
      const ChannelSlice& channel = slice.channel[c];
      if (channel.extra.size() > std::size_t{kMaxExtraComponents}) {
        return invalid(name + " channel " + "RGB"[c] + " has " +
                       std::to_string(channel.components()) + " components; at most " +
                       std::to_string(kMaxExtraComponents + 1) + " fit in a file");
      }
      for (int r = 0; r < channel.components(); ++r) {
        const Component& cs = channel.component(r);
        const std::string cname = name + " channel " + "RGB"[c] +
                                  (r > 0 ? " component " + std::to_string(r) : std::string());
        const Status st = check_channel_params(std::uint8_t(cs.family), cs.theta, cs.scale);
        if (!st.ok()) return invalid(cname + ": " + st.message());
        CBRDF_RETURN_IF_ERROR(check_table(cs.pdf_h, kThetaHBins, cname + " theta_h table"));
        CBRDF_RETURN_IF_ERROR(
            check_table(cs.pdf_d, std::size_t(slice.width()), cname + " theta_d table"));
        CBRDF_RETURN_IF_ERROR(check_table(cs.pdf_p, kPhiDBins, cname + " phi_d table"));
      }
    }
  }
  if (begin != kThetaDBins) {
    return invalid("slices end at theta_d bin " + std::to_string(begin) + ", not 90");
  }
  const NotMeasured& nm = model.not_measured;
  if (nm.bits.size() != (kMaskBits + 63) / 64) {
    return invalid("the not-measured mask has " + std::to_string(nm.bits.size()) +
                   " words, expected " + std::to_string((kMaskBits + 63) / 64));
  }
  if ((nm.bits.back() >> (kMaskBits % 64)) != 0) {
    return invalid("the not-measured mask has bits set past its last bin");
  }
  std::size_t count = 0;
  for (std::uint64_t w : nm.bits) count += std::size_t(std::popcount(w));
  if (nm.values.size() != 1 && nm.values.size() != count) {
    return invalid("the not-measured values list has " + std::to_string(nm.values.size()) +
                   " entries; expected 1 or one per not-measured bin (" + std::to_string(count) +
                   ")");
  }
  for (double v : nm.values) {
    if (v >= 0.0) {
      return invalid("not-measured value " + number_text(v) +
                     " is not negative (it would read as measured)");
    }
  }
  return check_residual(model);
}

}  // namespace cbrdf
