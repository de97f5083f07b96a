// SPDX-License-Identifier: MIT
// MASK's writer (spec 4.4): the not-measured mask (exact) and the stored values at its bins. It
// chooses the reference (none or the below-horizon mask) and the form (bitmap or runs) that make
// the mask smallest, so a standard MERL mask costs a few bytes.
#include <bit>

#include "bitstream/chunk_writers.h"
#include "byte_writer.h"

namespace cbrdf {
namespace {

// The lengths of the runs of equal bits in the first kMaskBits bits, alternately clear and set,
// starting with a clear run (possibly empty). Word by word: the next bit that differs from the
// current run's is the lowest set bit of the word XOR the run's fill.
std::vector<std::uint32_t> mask_runs(const std::vector<std::uint64_t>& coded) {
  std::vector<std::uint32_t> runs;
  bool current = false;
  std::size_t start = 0, b = 0;
  while (b < kMaskBits) {
    const std::uint64_t fill = current ? ~std::uint64_t{0} : 0;
    std::size_t w = b >> 6;
    std::uint64_t x = (coded[w] ^ fill) & (~std::uint64_t{0} << (b & 63));
    while (x == 0 && ++w < coded.size()) x = coded[w] ^ fill;
    const std::size_t next = x == 0 ? kMaskBits : 64 * w + std::size_t(std::countr_zero(x));
    if (next >= kMaskBits) break;  // bits past the mask (a set run's padding reads as a change)
    runs.push_back(std::uint32_t(next - start));
    start = b = next;
    current = !current;
  }
  runs.push_back(std::uint32_t(kMaskBits - start));
  return runs;
}

}  // namespace

std::vector<std::uint8_t> encode_mask_chunk(const NotMeasured& mask) {
  std::vector<std::uint64_t> xored = mask.bits;
  xor_below_horizon(&xored);
  std::size_t set = 0, set_xored = 0;
  for (std::size_t k = 0; k < mask.bits.size(); ++k) {
    set += std::size_t(std::popcount(mask.bits[k]));
    set_xored += std::size_t(std::popcount(xored[k]));
  }
  const bool use_reference = set_xored <= set;
  const std::vector<std::uint64_t>& coded = use_reference ? xored : mask.bits;

  const std::vector<std::uint32_t> runs = mask_runs(coded);
  std::size_t run_bytes = 4;
  for (std::uint32_t r : runs) run_bytes += varint_bytes(r);
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
