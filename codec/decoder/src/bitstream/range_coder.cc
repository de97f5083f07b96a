// SPDX-License-Identifier: MIT
#include "range_coder.h"

#include <string>

namespace cbrdf::internal {

Decoder::Decoder(std::span<const std::uint8_t> data) : data_(data) {
  for (int i = 0; i < 4; ++i) code_ = (code_ << 8) | next();
}

Status Decoder::finish() const {
  // The writer's flush emits 4 bytes the reader reads; trimmed zeros among them read past the end.
  if (past_end_ > 4) {
    return error(ErrorCode::kTruncated, "the coded stream ends " + std::to_string(past_end_ - 4) +
                                            " bytes before its last value");
  }
  if (pos_ < data_.size()) {
    return error(ErrorCode::kCorrupt, std::to_string(data_.size() - pos_) +
                                          " bytes after the coded stream's last value");
  }
  return ok_status();
}

Status get_uint(Decoder& d, UIntContexts& c, std::uint32_t* out) {
  int n = 0;
  while (d.bit(c.exponent[std::size_t(n)]) != 0) {
    if (++n > kMaxExponent - 1) {
      return error(ErrorCode::kCorrupt,
                   "a coded value's exponent exceeds " + std::to_string(kMaxExponent - 1));
    }
  }
  std::uint32_t x = 1;
  for (int i = n - 1; i >= 0; --i) {
    x = (x << 1) | std::uint32_t(d.bit(c.mantissa[std::size_t(n)][std::size_t(i)]));
  }
  *out = x - 1;
  return ok_status();
}

Status get_sint(Decoder& d, SIntContexts& c, std::int32_t* out) {
  if (d.bit(c.zero) == 0) {
    *out = 0;
    return ok_status();
  }
  const int negative = d.bit(c.sign);
  std::uint32_t m = 0;
  CBRDF_RETURN_IF_ERROR(get_uint(d, c.magnitude, &m));
  const std::int64_t v = std::int64_t(m) + 1;
  *out = std::int32_t(negative ? -v : v);
  return ok_status();
}

}  // namespace cbrdf::internal
