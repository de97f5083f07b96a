// SPDX-License-Identifier: MIT
// MODL's writer (spec 4.2): slice bounds and, per slice, channel and component, the copula
// family, its parameter and the scale K; and the container version a model needs.
#include "bitstream/chunk_writers.h"
#include "byte_writer.h"

namespace cbrdf {

bool has_mixtures(const Model& model) {
  for (const Slice& s : model.slices) {
    for (const ChannelSlice& c : s.channel) {
      if (!c.extra.empty()) return true;
    }
  }
  return false;
}

std::uint16_t container_minor(const Model& model) {
  return model.residual.present() ? 2 : has_mixtures(model) ? 1 : 0;
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
  // (A file of minor >= 1 holds the counts even when all are 0: a residual file without mixtures.)
  if (container_minor(model) == 0) return w.take();
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

}  // namespace cbrdf
