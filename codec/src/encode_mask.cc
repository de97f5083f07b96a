// The MASK payload writer: chooses the reference (none or the below-horizon mask) and the form
// (bitmap or runs) that make the mask smallest, so a standard MERL mask costs a few bytes.
#include <bit>

#include "byte_writer.h"
#include "decode_chunks.h"
#include "encode_chunks.h"

namespace cbrdf {
namespace {

bool get_bit(const std::vector<std::uint64_t>& bits, std::size_t b) {
  return (bits[b >> 6] >> (b & 63)) & 1u;
}

std::size_t varint_bytes(std::size_t v) {
  std::size_t n = 1;
  while (v >= 0x80) {
    v >>= 7;
    ++n;
  }
  return n;
}

}  // namespace

std::vector<std::uint8_t> encode_mask_chunk(const NotMeasured& mask) {
  const std::vector<std::uint64_t>& g = below_horizon_bits();
  std::vector<std::uint64_t> xored = mask.bits;
  for (int c = 0; c < kChannels; ++c) {
    const std::size_t base = std::size_t(c) * kBinsPerChannel;
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (get_bit(g, i)) xored[(base + i) >> 6] ^= std::uint64_t{1} << ((base + i) & 63);
    }
  }
  std::size_t set = 0, set_xored = 0;
  for (std::size_t k = 0; k < mask.bits.size(); ++k) {
    set += std::size_t(std::popcount(mask.bits[k]));
    set_xored += std::size_t(std::popcount(xored[k]));
  }
  const bool use_reference = set_xored <= set;
  const std::vector<std::uint64_t>& coded = use_reference ? xored : mask.bits;

  // Runs alternate clear/set starting with a clear run (possibly empty).
  std::vector<std::uint32_t> runs;
  std::size_t run_bytes = 4;
  bool current = false;
  std::uint32_t len = 0;
  for (std::size_t b = 0; b < kMaskBits; ++b) {
    if (get_bit(coded, b) != current) {
      runs.push_back(len);
      run_bytes += varint_bytes(len);
      current = !current;
      len = 0;
    }
    ++len;
  }
  runs.push_back(len);
  run_bytes += varint_bytes(len);
  const bool use_runs = run_bytes < kMaskBytes;

  const bool per_bin = mask.values.size() != 1;
  ByteWriter w;
  w.u8(std::uint8_t(use_reference ? MaskReference::kBelowHorizon : MaskReference::kNone));
  w.u8(std::uint8_t(use_runs ? MaskForm::kRuns : MaskForm::kBitmap));
  w.u8(std::uint8_t(per_bin ? MaskValues::kPerBin : MaskValues::kSingle));
  w.u8(0);
  w.u32(std::uint32_t(set));
  w.u64(mask_hash(mask.bits));
  if (use_runs) {
    w.u32(std::uint32_t(runs.size()));
    for (std::uint32_t r : runs) w.varint32(r);
  } else {
    for (std::size_t i = 0; i < kMaskBytes; ++i) w.u8(std::uint8_t(coded[i >> 3] >> (8 * (i & 7))));
  }
  for (double v : mask.values) w.f64(v);
  return w.take();
}

}  // namespace cbrdf
