// SPDX-License-Identifier: MIT
// MARG's writer (spec 4.3): the quantized marginal tables.
#include "bitstream/chunk_writers.h"
#include "bitstream/mass_quantizer.h"
#include "byte_writer.h"

namespace cbrdf {

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

}  // namespace cbrdf
