// SPDX-License-Identifier: MIT
// MODL (spec 4.2): slice bounds and, per slice, channel and component, the copula family,
// its parameter and the scale K. The reader (the writer is the encoder's, modl_writer.cc).
#include <string>

#include "byte_reader.h"
#include "chunks.h"

namespace cbrdf {
namespace {

// One component's family, parameter and scale (MODL), validated; `where` names it in errors.
Status read_component(ByteReader* r, const std::string& where, Component* out) {
  std::uint8_t family = 0;
  double theta = 0.0, scale = 0.0;
  CBRDF_RETURN_IF_ERROR(r->u8(&family, "copula family"));
  CBRDF_RETURN_IF_ERROR(r->f64(&theta, "copula parameter"));
  CBRDF_RETURN_IF_ERROR(r->f64(&scale, "scale K"));
  if (Status st = check_channel_params(family, theta, scale); !st.ok()) {
    return st.with_context(where);
  }
  out->family = CopulaFamily(family);
  out->theta = theta;
  out->scale = scale;
  return Status();
}

}  // namespace

Status read_slice_bounds(ByteReader& r, int slice_count, std::vector<Slice>* slices) {
  slices->assign(std::size_t(slice_count), Slice{});
  int begin = 0;
  for (int s = 0; s < slice_count; ++s) {
    std::uint8_t end = 0;
    CBRDF_RETURN_IF_ERROR(r.u8(&end, "slice end"));
    if (end <= begin || end > kThetaDBins || (s + 1 == slice_count && end != kThetaDBins)) {
      return error(ErrorCode::kCorrupt, "slice " + std::to_string(s) + " ends at theta_d bin " +
                                            std::to_string(end) + " after starting at " +
                                            std::to_string(begin) +
                                            "; slices must be non-empty, contiguous and end at 90");
    }
    (*slices)[std::size_t(s)].theta_d_begin = begin;
    (*slices)[std::size_t(s)].theta_d_end = end;
    begin = end;
  }
  return ok_status();
}

Status read_component_counts(ByteReader& r, std::vector<Slice>* slices) {
  for (int s = 0; s < int(slices->size()); ++s) {
    for (int c = 0; c < kChannels; ++c) {
      std::uint8_t count = 0;
      CBRDF_RETURN_IF_ERROR(r.u8(&count, "further component count"));
      if (count > kMaxExtraComponents) {
        return error(ErrorCode::kCorrupt, "slice " + std::to_string(s) + " channel " +
                                              kChannelNames[c] + " has " + std::to_string(count) +
                                              " further components; at most " +
                                              std::to_string(kMaxExtraComponents) + " are allowed");
      }
      (*slices)[std::size_t(s)].channel[std::size_t(c)].extra.resize(count);
    }
  }
  return ok_status();
}

Status decode_model_chunk(std::span<const std::uint8_t> payload, std::uint16_t file_minor,
                          int slice_count, std::vector<Slice>* slices) {
  ByteReader r = payload_reader(payload);
  CBRDF_RETURN_IF_ERROR(read_slice_bounds(r, slice_count, slices));
  for (int s = 0; s < slice_count; ++s) {
    for (int c = 0; c < kChannels; ++c) {
      ChannelSlice& cs = (*slices)[std::size_t(s)].channel[std::size_t(c)];
      CBRDF_RETURN_IF_ERROR(
          read_component(&r, "slice " + std::to_string(s) + " channel " + kChannelNames[c], &cs));
    }
  }
  if (file_minor >= 1) {
    // Version 1.1: further components per slice and channel, counts first.
    CBRDF_RETURN_IF_ERROR(read_component_counts(r, slices));
    for (int s = 0; s < slice_count; ++s) {
      for (int c = 0; c < kChannels; ++c) {
        auto& extra = (*slices)[std::size_t(s)].channel[std::size_t(c)].extra;
        for (std::size_t e = 0; e < extra.size(); ++e) {
          CBRDF_RETURN_IF_ERROR(read_component(&r,
                                               "slice " + std::to_string(s) + " channel " +
                                                   kChannelNames[c] + " component " +
                                                   std::to_string(e + 1),
                                               &extra[e]));
        }
      }
    }
  }
  return check_trailing(r.remaining(), file_minor);
}

}  // namespace cbrdf
