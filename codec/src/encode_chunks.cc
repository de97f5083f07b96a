// Writers of the HEAD, MODL, MARG and mETA payloads (spec/container.md).
#include "encode_chunks.h"

#include "byte_writer.h"
#include "decode_chunks.h"
#include "quantize.h"

namespace cbrdf {

bool has_mixtures(const Model& model) {
  for (const Slice& s : model.slices) {
    for (const ChannelSlice& c : s.channel) {
      if (!c.extra.empty()) return true;
    }
  }
  return false;
}

std::vector<std::uint8_t> encode_header_chunk(const Model& model) {
  ByteWriter w;
  w.u16(kThetaHBins);
  w.u16(kThetaDBins);
  w.u16(kPhiDBins);
  w.u8(kThetaHMappingMerlSqrt);
  w.u8(kChannels);
  for (double s : kMerlScale) w.f64(s);
  w.u16(std::uint16_t(model.slices.size()));
  return w.take();
}

std::vector<std::uint8_t> encode_model_chunk(const Model& model) {
  ByteWriter w;
  for (const Slice& s : model.slices) w.u8(std::uint8_t(s.theta_d_end));
  for (const Slice& s : model.slices) {
    for (const ChannelSlice& c : s.channel) {
      w.u8(std::uint8_t(c.family));
      w.f64(c.theta);
      w.f64(c.scale);
    }
  }
  // Version 1.1: the number of further components of every slice and channel, then theirs.
  if (!has_mixtures(model)) return w.take();
  for (const Slice& s : model.slices) {
    for (const ChannelSlice& c : s.channel) w.u8(std::uint8_t(c.extra.size()));
  }
  for (const Slice& s : model.slices) {
    for (const ChannelSlice& c : s.channel) {
      for (const Component& e : c.extra) {
        w.u8(std::uint8_t(e.family));
        w.f64(e.theta);
        w.f64(e.scale);
      }
    }
  }
  return w.take();
}

std::vector<std::uint8_t> encode_marginals_chunk(const Model& model, int bits) {
  std::vector<QuantizedTable> tables;
  for (const Slice& s : model.slices) {
    for (const ChannelSlice& c : s.channel) {
      for (int r = 0; r < c.components(); ++r) {
        const Component& comp = c.component(r);
        for (const std::vector<double>* t : {&comp.pdf_h, &comp.pdf_d, &comp.pdf_p}) {
          tables.push_back(quantize_masses(*t, bits));
        }
      }
    }
  }
  ByteWriter w;
  w.u8(std::uint8_t(bits));
  w.u8(has_mixtures(model) ? kMarginalLayoutComponents : kMarginalLayoutSingle);
  w.u16(std::uint16_t(tables.size()));
  // Ranges first, then all codes: like data next to like data compresses better under zstd.
  for (const QuantizedTable& t : tables) {
    w.f32(t.lo);
    w.f32(t.hi);
  }
  for (const QuantizedTable& t : tables) {
    std::int32_t prev = 0;
    for (std::uint32_t q : t.codes) {
      w.varint32(zigzag(std::int32_t(q) - prev));
      prev = std::int32_t(q);
    }
  }
  return w.take();
}

std::vector<std::uint8_t> encode_metadata_chunk(
    const std::vector<std::pair<std::string, std::string>>& entries) {
  std::vector<std::uint8_t> out;
  for (const auto& [key, value] : entries) {
    out.insert(out.end(), key.begin(), key.end());
    out.push_back('=');
    out.insert(out.end(), value.begin(), value.end());
    out.push_back('\n');
  }
  return out;
}

}  // namespace cbrdf
