// SPDX-License-Identifier: MIT
// HEAD's writer (spec 4.1): the grid, the colour scales and the slice count.
#include "bitstream/chunk_writers.h"
#include "byte_writer.h"

namespace cbrdf {

std::vector<std::uint8_t> encode_header_chunk(const Model& model, bool compact) {
  ByteWriter w;
  if (compact) {
    w.u8(kGridMerl);
    w.u8(std::uint8_t(model.slices.size()));
    return w.take();
  }
  w.u16(kThetaHBins);
  w.u16(kThetaDBins);
  w.u16(kPhiDBins);
  w.u8(kThetaHMappingMerlSqrt);
  w.u8(kChannels);
  for (double s : kMerlScale) w.f64(s);
  w.u16(std::uint16_t(model.slices.size()));
  return w.take();
}

}  // namespace cbrdf
