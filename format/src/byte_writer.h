// SPDX-License-Identifier: MIT
// The little-endian writer behind every cbrdf serializer (the counterpart of ByteReader).
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

namespace cbrdf {

// The bytes ByteWriter::varint32 (unsigned LEB128) takes for v: a writer's size estimate.
inline std::size_t varint_bytes(std::uint64_t v) {
  std::size_t n = 1;
  while (v >= 0x80) {
    v >>= 7;
    ++n;
  }
  return n;
}

class ByteWriter {
 public:
  void u8(std::uint8_t v) { buf_.push_back(v); }
  void u16(std::uint16_t v) { little_endian(v); }
  void u32(std::uint32_t v) { little_endian(v); }
  void u64(std::uint64_t v) { little_endian(v); }
  void f32(float v) { little_endian(std::bit_cast<std::uint32_t>(v)); }
  void f64(double v) { little_endian(std::bit_cast<std::uint64_t>(v)); }
  void bytes(std::span<const std::uint8_t> b) { buf_.insert(buf_.end(), b.begin(), b.end()); }
  // Unsigned LEB128, the shortest encoding (ByteReader::varint32 refuses any other).
  void varint32(std::uint32_t v) {
    while (v >= 0x80) {
      buf_.push_back(std::uint8_t(v | 0x80));
      v >>= 7;
    }
    buf_.push_back(std::uint8_t(v));
  }

  std::size_t size() const { return buf_.size(); }
  const std::vector<std::uint8_t>& data() const { return buf_; }
  std::vector<std::uint8_t> take() { return std::move(buf_); }

 private:
  template <typename T>
  void little_endian(T v) {
    for (std::size_t i = 0; i < sizeof(T); ++i) buf_.push_back(std::uint8_t(v >> (8 * i)));
  }
  std::vector<std::uint8_t> buf_;
};

}  // namespace cbrdf
