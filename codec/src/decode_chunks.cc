// Parsers of the HEAD, MODL, MARG and mETA payloads (spec/container.md).
#include "decode_chunks.h"

#include <string>

#include "byte_reader.h"
#include "cbrdf/container.h"

namespace cbrdf {
namespace {

const char* const kChannelNames[kChannels] = {"R", "G", "B"};
const char* const kAxisNames[3] = {"theta_h", "theta_d", "phi_d"};

ByteReader payload_reader(std::span<const std::uint8_t> payload) {
  return ByteReader(payload, 0, "payload offset");
}

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

Status decode_header_chunk(std::span<const std::uint8_t> payload, std::uint16_t file_minor,
                           HeaderFields* out) {
  ByteReader r = payload_reader(payload);
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

Status decode_model_chunk(std::span<const std::uint8_t> payload, std::uint16_t file_minor,
                          int slice_count, std::vector<Slice>* slices) {
  ByteReader r = payload_reader(payload);
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
  for (int s = 0; s < slice_count; ++s) {
    for (int c = 0; c < kChannels; ++c) {
      ChannelSlice& cs = (*slices)[std::size_t(s)].channel[std::size_t(c)];
      CBRDF_RETURN_IF_ERROR(
          read_component(&r, "slice " + std::to_string(s) + " channel " + kChannelNames[c], &cs));
    }
  }
  if (file_minor >= 1) {
    // Version 1.1: further components per slice and channel, counts first.
    for (int s = 0; s < slice_count; ++s) {
      for (int c = 0; c < kChannels; ++c) {
        std::uint8_t count = 0;
        CBRDF_RETURN_IF_ERROR(r.u8(&count, "further component count"));
        if (count > kMaxExtraComponents) {
          return error(ErrorCode::kCorrupt,
                       "slice " + std::to_string(s) + " channel " + kChannelNames[c] + " has " +
                           std::to_string(count) + " further components; at most " +
                           std::to_string(kMaxExtraComponents) + " are allowed");
        }
        (*slices)[std::size_t(s)].channel[std::size_t(c)].extra.resize(count);
      }
    }
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

Status decode_marginals_chunk(std::span<const std::uint8_t> payload, std::uint16_t file_minor,
                              std::vector<Slice>* slices, int* bits_out) {
  ByteReader r = payload_reader(payload);
  std::uint8_t bits = 0, reserved = 0;
  std::uint16_t table_count = 0;
  CBRDF_RETURN_IF_ERROR(r.u8(&bits, "bits per code"));
  CBRDF_RETURN_IF_ERROR(r.u8(&reserved, "reserved byte"));
  CBRDF_RETURN_IF_ERROR(r.u16(&table_count, "table count"));
  if (bits < kMinMarginalBits || bits > kMaxMarginalBits) {
    return error(ErrorCode::kCorrupt, "bits per code " + std::to_string(bits) + " is outside " +
                                          std::to_string(kMinMarginalBits) + ".." +
                                          std::to_string(kMaxMarginalBits));
  }
  std::size_t components = 0;
  for (const Slice& slice : *slices) {
    for (const ChannelSlice& cs : slice.channel) components += std::size_t(cs.components());
  }
  const bool mixtures = components > slices->size() * kChannels;
  if (file_minor == 0 && reserved != 0) {
    return error(ErrorCode::kCorrupt, "reserved byte at payload offset 1 is not 0");
  }
  if (reserved != (mixtures ? kMarginalLayoutComponents : kMarginalLayoutSingle)) {
    return error(ErrorCode::kCorrupt, "table layout byte at payload offset 1 is " +
                                          std::to_string(reserved) + "; it must be " +
                                          (mixtures ? "1: MODL declares further components"
                                                    : "0: MODL declares no further components"));
  }
  const std::size_t expected_tables = components * 3;
  if (table_count != expected_tables) {
    return error(ErrorCode::kCorrupt,
                 "table count " + std::to_string(table_count) + " does not match " +
                     (mixtures ? std::to_string(components) + " components x 3 axes"
                               : std::to_string(slices->size()) + " slices x 3 channels x 3 axes"));
  }
  std::vector<QuantizedTable> tables(expected_tables);
  for (QuantizedTable& t : tables) {
    CBRDF_RETURN_IF_ERROR(r.f32(&t.lo, "table range lo"));
    CBRDF_RETURN_IF_ERROR(r.f32(&t.hi, "table range hi"));
  }
  std::size_t t_index = 0;
  const std::int64_t top = max_code(bits);
  for (std::size_t s = 0; s < slices->size(); ++s) {
    Slice& slice = (*slices)[s];
    for (int c = 0; c < kChannels; ++c) {
      ChannelSlice& channel = slice.channel[std::size_t(c)];
      for (int comp = 0; comp < channel.components(); ++comp) {
        Component& cs = channel.component(comp);
        std::vector<double>* axes[3] = {&cs.pdf_h, &cs.pdf_d, &cs.pdf_p};
        const int sizes[3] = {kThetaHBins, slice.width(), kPhiDBins};
        for (int a = 0; a < 3; ++a, ++t_index) {
          QuantizedTable& t = tables[t_index];
          const std::string where =
              "slice " + std::to_string(s) + " channel " + kChannelNames[c] +
              (comp > 0 ? " component " + std::to_string(comp) : std::string()) + " " +
              kAxisNames[a] + " table";
          t.codes.resize(std::size_t(sizes[a]));
          std::int64_t prev = 0;
          for (std::uint32_t& q : t.codes) {
            std::uint32_t z = 0;
            const std::uint64_t at = r.offset();
            CBRDF_RETURN_IF_ERROR(r.varint32(&z, "code residual"));
            const std::int64_t code = prev + unzigzag(z);
            if (code < 0 || code > top) {
              return error(ErrorCode::kCorrupt, where + ": residual at payload offset " +
                                                    std::to_string(at) + " gives code " +
                                                    std::to_string(code) + " outside 0.." +
                                                    std::to_string(top));
            }
            q = std::uint32_t(code);
            prev = code;
          }
          Expected<std::vector<double>> m = dequantize_masses(t, bits);
          if (!m.ok()) return m.status().with_context(where);
          *axes[a] = std::move(m.value());
        }
      }
    }
  }
  *bits_out = bits;
  return check_trailing(r.remaining(), file_minor);
}

Status decode_metadata_chunk(std::span<const std::uint8_t> payload,
                             std::vector<std::pair<std::string, std::string>>* out) {
  out->clear();
  std::size_t pos = 0;
  while (pos < payload.size()) {
    if (out->size() == kMaxMetadataEntries) {
      return error(ErrorCode::kLimit,
                   "more than " + std::to_string(kMaxMetadataEntries) + " metadata entries");
    }
    const std::size_t line_start = pos;
    std::size_t eq = pos;
    while (eq < payload.size() && payload[eq] != '=' && payload[eq] != '\n') ++eq;
    if (eq == payload.size() || payload[eq] != '=') {
      return error(ErrorCode::kCorrupt,
                   "metadata line at payload offset " + std::to_string(line_start) + " has no '='");
    }
    std::string key(payload.begin() + std::ptrdiff_t(pos), payload.begin() + std::ptrdiff_t(eq));
    if (key.empty() || key.size() > kMaxMetadataKeyBytes) {
      return error(ErrorCode::kCorrupt, "metadata key at payload offset " +
                                            std::to_string(line_start) +
                                            " is empty or longer than " +
                                            std::to_string(kMaxMetadataKeyBytes) + " bytes");
    }
    for (char ch : key) {
      const bool ok =
          (ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '_' || ch == '.';
      if (!ok) {
        return error(ErrorCode::kCorrupt, "metadata key at payload offset " +
                                              std::to_string(line_start) +
                                              " has a character outside [a-z0-9_.]");
      }
    }
    for (const auto& kv : *out) {
      if (kv.first == key) {
        return error(ErrorCode::kCorrupt, "metadata key '" + key + "' at payload offset " +
                                              std::to_string(line_start) + " appears twice");
      }
    }
    std::size_t nl = eq + 1;
    while (nl < payload.size() && payload[nl] != '\n') {
      if (payload[nl] < 0x20 || payload[nl] == 0x7F) {
        return error(ErrorCode::kCorrupt, "metadata value at payload offset " + std::to_string(nl) +
                                              " has a control character");
      }
      ++nl;
    }
    if (nl == payload.size()) {
      return error(ErrorCode::kCorrupt, "metadata line at payload offset " +
                                            std::to_string(line_start) +
                                            " is not terminated by LF");
    }
    if (nl - eq - 1 > kMaxMetadataValueBytes) {
      return error(ErrorCode::kCorrupt, "metadata value at payload offset " +
                                            std::to_string(eq + 1) + " is longer than " +
                                            std::to_string(kMaxMetadataValueBytes) + " bytes");
    }
    out->emplace_back(std::move(key), std::string(payload.begin() + std::ptrdiff_t(eq + 1),
                                                  payload.begin() + std::ptrdiff_t(nl)));
    pos = nl + 1;
  }
  return ok_status();
}

}  // namespace cbrdf
