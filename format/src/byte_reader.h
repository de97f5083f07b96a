// SPDX-License-Identifier: MIT
// The bounds-checked little-endian reader every cbrdf parser goes through.
//
// Each read checks the remaining length first and reports kTruncated with the offset and the
// number of bytes needed, so that no parser indexes a buffer by hand. Offsets are reported from
// `base_offset`, which lets a reader over a chunk payload name positions in file terms.
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>

#include "cbrdf/status.h"

namespace cbrdf {

class ByteReader {
 public:
  // `offset_label` names the frame of reference in messages ("offset", "payload offset").
  explicit ByteReader(std::span<const std::uint8_t> data, std::uint64_t base_offset = 0,
                      const char* offset_label = "offset")
      : data_(data), base_(base_offset), label_(offset_label) {}

  std::size_t remaining() const { return data_.size() - pos_; }
  std::size_t position() const { return pos_; }
  // Position in the caller's frame of reference (e.g. the byte offset in the file).
  std::uint64_t offset() const { return base_ + pos_; }
  bool at_end() const { return pos_ == data_.size(); }

  // Fails with kTruncated naming `what` when fewer than n bytes are left.
  Status need(std::size_t n, const char* what) const {
    if (n <= remaining()) return ok_status();
    return error(ErrorCode::kTruncated, std::string(what) + " needs " + std::to_string(n) +
                                            " bytes at " + label_ + " " + std::to_string(offset()) +
                                            " but only " + std::to_string(remaining()) +
                                            " are left");
  }

  Status bytes(std::size_t n, std::span<const std::uint8_t>* out, const char* what) {
    CBRDF_RETURN_IF_ERROR(need(n, what));
    *out = data_.subspan(pos_, n);
    pos_ += n;
    return ok_status();
  }
  Status skip(std::size_t n, const char* what) {
    CBRDF_RETURN_IF_ERROR(need(n, what));
    pos_ += n;
    return ok_status();
  }

  Status u8(std::uint8_t* out, const char* what) { return little_endian(out, what); }
  Status u16(std::uint16_t* out, const char* what) { return little_endian(out, what); }
  Status u32(std::uint32_t* out, const char* what) { return little_endian(out, what); }
  Status u64(std::uint64_t* out, const char* what) { return little_endian(out, what); }
  Status f32(float* out, const char* what) {
    std::uint32_t bits = 0;
    CBRDF_RETURN_IF_ERROR(u32(&bits, what));
    *out = std::bit_cast<float>(bits);
    return ok_status();
  }
  Status f64(double* out, const char* what) {
    std::uint64_t bits = 0;
    CBRDF_RETURN_IF_ERROR(u64(&bits, what));
    *out = std::bit_cast<double>(bits);
    return ok_status();
  }

  // Unsigned LEB128 of at most 5 bytes holding a value below 2^32. Overlong encodings (a final
  // zero byte after the first) are refused so that every value has exactly one encoding.
  Status varint32(std::uint32_t* out, const char* what) {
    const std::uint64_t start = offset();
    std::uint64_t value = 0;
    for (int i = 0; i < 5; ++i) {
      std::uint8_t b = 0;
      CBRDF_RETURN_IF_ERROR(u8(&b, what));
      value |= std::uint64_t(b & 0x7F) << (7 * i);
      if ((b & 0x80) == 0) {
        if (i > 0 && b == 0) return bad_varint(start, what, "is overlong");
        if (value > 0xFFFFFFFFu) return bad_varint(start, what, "exceeds 2^32-1");
        *out = std::uint32_t(value);
        return ok_status();
      }
    }
    return bad_varint(start, what, "is longer than 5 bytes");
  }

 private:
  template <typename T>
  Status little_endian(T* out, const char* what) {
    CBRDF_RETURN_IF_ERROR(need(sizeof(T), what));
    T v = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i) v = T(v | (T(data_[pos_ + i]) << (8 * i)));
    pos_ += sizeof(T);
    *out = v;
    return ok_status();
  }
  Status bad_varint(std::uint64_t start, const char* what, const char* problem) const {
    return error(ErrorCode::kCorrupt, std::string(what) + " at " + label_ + " " +
                                          std::to_string(start) + ": varint " + problem);
  }

  std::span<const std::uint8_t> data_;
  std::uint64_t base_ = 0;
  const char* label_ = "offset";
  std::size_t pos_ = 0;
};

}  // namespace cbrdf
