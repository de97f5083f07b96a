// SPDX-License-Identifier: MIT
// HEAD (spec 4.1): the grid, the colour scales and the slice count. The reader (the writer is the
// encoder's, head_writer.cc).
#include <string>

#include "byte_reader.h"
#include "chunks.h"

namespace cbrdf {
Status decode_header_chunk(std::span<const std::uint8_t> payload, std::uint16_t file_minor,
                           bool compact, HeaderFields* out) {
  ByteReader r = payload_reader(payload);
  if (compact) {
    // Version 1.3, a file with BASE: the one grid this version defines, by number, and the slice
    // count.
    std::uint8_t grid = 0, count = 0;
    CBRDF_RETURN_IF_ERROR(r.u8(&grid, "grid"));
    CBRDF_RETURN_IF_ERROR(r.u8(&count, "slice count"));
    CBRDF_RETURN_IF_ERROR(check_trailing(r.remaining(), file_minor));
    if (grid != kGridMerl) {
      return error(ErrorCode::kUnsupported,
                   "grid " + std::to_string(grid) +
                       " is unknown (0 = MERL's 90x90x180 RGB grid, the one this reader supports)");
    }
    if (count < 1 || count > kThetaDBins) {
      return error(ErrorCode::kCorrupt,
                   "slice count " + std::to_string(count) + " is outside 1..90");
    }
    out->colour_scale = kMerlScale;
    out->slice_count = count;
    return ok_status();
  }
  std::uint16_t nh = 0, nd = 0, np = 0, slices = 0;
  std::uint8_t mapping = 0, channels = 0;
  CBRDF_RETURN_IF_ERROR(r.u16(&nh, "theta_h bin count"));
  CBRDF_RETURN_IF_ERROR(r.u16(&nd, "theta_d bin count"));
  CBRDF_RETURN_IF_ERROR(r.u16(&np, "phi_d bin count"));
  CBRDF_RETURN_IF_ERROR(r.u8(&mapping, "theta_h mapping"));
  CBRDF_RETURN_IF_ERROR(r.u8(&channels, "channel count"));
  for (int c = 0; c < kChannels; ++c) {
    CBRDF_RETURN_IF_ERROR(r.f64(&out->colour_scale[std::size_t(c)], "colour scale factor"));
  }
  CBRDF_RETURN_IF_ERROR(r.u16(&slices, "slice count"));
  CBRDF_RETURN_IF_ERROR(check_trailing(r.remaining(), file_minor));
  if (nh != kThetaHBins || nd != kThetaDBins || np != kPhiDBins) {
    return error(ErrorCode::kUnsupported,
                 "grid " + std::to_string(nh) + "x" + std::to_string(nd) + "x" +
                     std::to_string(np) + " is not the MERL grid 90x90x180 this reader supports");
  }
  if (mapping != kThetaHMappingMerlSqrt) {
    return error(ErrorCode::kUnsupported, "theta_h mapping " + std::to_string(mapping) +
                                              " is unknown (0 = the MERL square-root mapping)");
  }
  if (channels != kChannels) {
    return error(ErrorCode::kUnsupported,
                 std::to_string(channels) + " colour channels; this reader supports 3 (RGB)");
  }
  for (int c = 0; c < kChannels; ++c) {
    if (out->colour_scale[std::size_t(c)] != kMerlScale[std::size_t(c)]) {
      return error(ErrorCode::kUnsupported,
                   std::string("colour scale factor of ") + kChannelNames[c] + " is " +
                       number_text(out->colour_scale[std::size_t(c)]) +
                       "; this reader supports only MERL's (1, 1.15, 1.66) / 1500");
    }
  }
  if (slices < 1 || slices > kThetaDBins) {
    return error(ErrorCode::kCorrupt,
                 "slice count " + std::to_string(slices) + " is outside 1..90");
  }
  out->slice_count = slices;
  return ok_status();
}

}  // namespace cbrdf
