// SPDX-License-Identifier: MIT
#include "bitstream/range_encoder.h"

namespace cbrdf::internal {

void Encoder::shift_low() {
  // A byte is final once no carry can reach it: low below 0xFF000000, or a carry just happened.
  if (std::uint32_t(low_) < 0xFF000000u || (low_ >> 32) != 0) {
    const auto carry = std::uint8_t(low_ >> 32);
    std::uint8_t temp = cache_;
    do {
      out_.push_back(std::uint8_t(temp + carry));
      temp = 0xFF;
    } while (--cache_size_ != 0);
    cache_ = std::uint8_t(low_ >> 24);
  }
  ++cache_size_;
  low_ = (low_ & 0x00FFFFFFu) << 8;
}

std::vector<std::uint8_t> Encoder::finish() {
  for (int i = 0; i < 5; ++i) shift_low();
  // The first byte is the initial cache, always 0 (low starts at 0 and never carries into it).
  std::vector<std::uint8_t> out(out_.begin() + 1, out_.end());
  // At most the 4 flushed bytes are trimmed, so a reader never needs more than 4 zeros past the
  // end.
  for (int i = 0; i < 4 && !out.empty() && out.back() == 0; ++i) out.pop_back();
  return out;
}

}  // namespace cbrdf::internal
