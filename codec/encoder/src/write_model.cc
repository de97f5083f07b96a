// SPDX-License-Identifier: MIT
// encode_model: validates the model against what a file can hold, then writes the chunks.
#include <algorithm>
#include <bit>
#include <cmath>
#include <string>

#include "bitstream/chunk_writers.h"
#include "bitstream/residual_levels_writer.h"
#include "cbrdf/codec.h"
#include "cbrdf/container.h"
#include "cbrdf/container_writer.h"
#include "cbrdf/version.h"
#include "utf8.h"

namespace cbrdf {
namespace {

Status invalid(std::string message) {
  return error(ErrorCode::kInvalidArgument, "cannot encode: " + std::move(message));
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

Status check_model(const Model& model) {
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

// Metadata is UTF-8 text without control characters (spec 4.5): a file name from any filesystem
// is stored with invalid bytes as U+FFFD and control characters as '?'.
std::string sanitized(const std::string& s) {
  std::string out = valid_utf8(s, kMaxMetadataValueBytes);
  for (char& ch : out) {
    if (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7F) ch = '?';
  }
  return out;
}

// HEAD, MODL and MARG as versions 1.0-1.2 write them. MODL is small and mostly doubles: zstd
// rarely pays, and the writer keeps it only when it does.
std::vector<ChunkToWrite> old_model_chunks(const Model& model, int bits) {
  std::vector<ChunkToWrite> chunks;
  chunks.push_back({std::string(kTagHeader), encode_header_chunk(model, false), false});
  chunks.push_back({std::string(kTagModel), encode_model_chunk(model), true});
  chunks.push_back({std::string(kTagMarginals), encode_marginals_chunk(model, bits), true});
  return chunks;
}

}  // namespace

Expected<std::vector<std::uint8_t>> encode_model(const Model& model,
                                                 const ContainerSettings& settings) {
  if (settings.bits < kMinMarginalBits || settings.bits > kMaxMarginalBits) {
    return invalid("bits per code " + std::to_string(settings.bits) + " is outside " +
                   std::to_string(kMinMarginalBits) + ".." + std::to_string(kMaxMarginalBits));
  }
  if (settings.zstd_level < 1 || settings.zstd_level > 22) {
    return invalid("zstd level " + std::to_string(settings.zstd_level) + " is outside 1..22");
  }
  CBRDF_RETURN_IF_ERROR(check_model(model));

  // The model's own chunks in both codings; 1.3 where smaller (by the model chunks alone, so
  // that a residual file's base decodes as the file without the residual did), or where the
  // residual needs it.
  const std::uint16_t old_minor = container_minor(model);
  std::vector<ChunkToWrite> model_chunks;
  std::uint16_t minor = old_minor;
  if (settings.format != ContainerSettings::Format::kV12) {
    std::optional<std::vector<std::uint8_t>> base = encode_base_chunk(model, settings.bits);
    if (base) {
      std::vector<ChunkToWrite> v13;
      v13.push_back({std::string(kTagHeader), encode_header_chunk(model, true), false});
      v13.push_back({std::string(kTagBase), std::move(*base), false});
      // A residual with middle levels' steps (mode 4) exists only in 1.3.
      if (settings.format == ContainerSettings::Format::kV13 || model.residual.middle_steps()) {
        model_chunks = std::move(v13);
        minor = 3;
      } else {
        Expected<std::vector<std::uint8_t>> a = write_container(v13, settings.zstd_level, 3);
        Expected<std::vector<std::uint8_t>> b =
            write_container(old_model_chunks(model, settings.bits), settings.zstd_level, old_minor);
        if (!a.ok()) return a.status();
        if (!b.ok()) return b.status();
        if (a->size() < b->size()) {
          model_chunks = std::move(v13);
          minor = 3;
        }
      }
    }
  }
  if (model_chunks.empty()) model_chunks = old_model_chunks(model, settings.bits);
  if (model.residual.middle_steps() && minor < 3) {
    return invalid(
        "the residual's multipliers of middle levels (RESD mode 4) need container version 1.3, "
        "and this file is written as 1." +
        std::to_string(minor) + " (--format-version 1.2, or a model 1.3 cannot code)");
  }
  std::vector<ChunkToWrite> chunks = std::move(model_chunks);
  // One stored value per not-measured bin makes MASK up to 35 MB; zstd's top levels take minutes
  // on that for a few percent, so the level is capped for this chunk (a uniform value is tiny).
  chunks.push_back({std::string(kTagMask), encode_mask_chunk(model.not_measured), true, 9});
  if (model.residual.present()) {
    // The exact table's streams are zstd frames already.
    chunks.push_back({std::string(kTagResidual), encode_residual_chunk(model, minor >= 3),
                      model.residual.exact == nullptr, kResidualZstdLevel});
  }
  if (settings.write_metadata) {
    std::vector<std::pair<std::string, std::string>> meta;
    if (!settings.source_name.empty()) meta.emplace_back("source", sanitized(settings.source_name));
    meta.emplace_back("encoder", std::string("cbrdf ") + CBRDF_VERSION_STRING);
    if (settings.metadata == ContainerSettings::Metadata::kFull) {
      meta.emplace_back("bits", std::to_string(settings.bits));
      meta.emplace_back("zstd_level", std::to_string(settings.zstd_level));
    }
    chunks.push_back({std::string(kTagMetadata), encode_metadata_chunk(meta), true});
  }
  // The lowest version that holds the model: files without mixtures stay readable by 1.0 readers.
  return write_container(chunks, settings.zstd_level, minor);
}

}  // namespace cbrdf
