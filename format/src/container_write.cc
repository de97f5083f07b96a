// SPDX-License-Identifier: MIT
// The container writer: the file header, chunks (zstd where it pays) and the end chunk, in the
// framing of 1.0-1.2 or the compact one of 1.3.
#include <algorithm>
#include <string>

#include "byte_writer.h"
#include "cbrdf/container.h"
#include "zstd_util.h"

namespace cbrdf {
namespace {

// Tag and length field, and the payload length field of a compressed chunk.
std::size_t compact_frame_bytes(std::size_t stored, bool compressed, std::uint32_t payload_bytes) {
  return 4 + varint_bytes(std::uint64_t(stored) << 2) +
         (compressed ? varint_bytes(payload_bytes) : 0);
}

}  // namespace

std::vector<std::uint8_t> container_file_header(std::uint16_t major, std::uint16_t minor) {
  ByteWriter w;
  w.bytes(kContainerSignature);
  w.u16(major);
  w.u16(minor);
  return w.take();
}

void append_raw_chunk(std::vector<std::uint8_t>* out, std::string_view tag, std::uint32_t flags,
                      std::span<const std::uint8_t> stored, std::uint32_t payload_bytes) {
  ByteWriter w;
  for (std::size_t i = 0; i < 4; ++i) w.u8(i < tag.size() ? std::uint8_t(tag[i]) : 0);
  w.u32(std::uint32_t(stored.size()));
  w.u32(flags);
  w.u32(payload_bytes);
  w.bytes(stored);
  w.u64(chunk_checksum(w.data()));
  out->insert(out->end(), w.data().begin(), w.data().end());
}

void append_compact_chunk(std::vector<std::uint8_t>* out, std::string_view tag, std::uint32_t flags,
                          std::span<const std::uint8_t> stored, std::uint32_t payload_bytes) {
  ByteWriter w;
  for (std::size_t i = 0; i < 4; ++i) w.u8(i < tag.size() ? std::uint8_t(tag[i]) : 0);
  w.varint32(std::uint32_t(stored.size() << 2) | (flags & 3u));
  if ((flags & kChunkFlagZstd) != 0) w.varint32(payload_bytes);
  w.bytes(stored);
  out->insert(out->end(), w.data().begin(), w.data().end());
}

void append_compact_end(std::vector<std::uint8_t>* out) {
  append_compact_chunk(out, kTagEnd, 0, {}, 0);
  const std::uint32_t sum = file_checksum(*out);
  for (int i = 0; i < 4; ++i) out->push_back(std::uint8_t(sum >> (8 * i)));
}

Expected<std::vector<std::uint8_t>> write_container(std::span<const ChunkToWrite> chunks,
                                                    int zstd_level, std::uint16_t minor) {
  if (minor > kContainerMinorVersion) {
    return error(ErrorCode::kInvalidArgument, "cannot write minor version " +
                                                  std::to_string(minor) + ": this writer knows 1." +
                                                  std::to_string(kContainerMinorVersion));
  }
  std::vector<std::uint8_t> out = container_file_header(kContainerMajorVersion, minor);
  const bool compact = uses_compact_framing(minor);
  auto append = [&](std::string_view tag, std::uint32_t flags, std::span<const std::uint8_t> stored,
                    std::uint32_t payload_bytes) {
    if (compact) {
      append_compact_chunk(&out, tag, flags, stored, payload_bytes);
    } else {
      append_raw_chunk(&out, tag, flags, stored, payload_bytes);
    }
  };
  for (const ChunkToWrite& c : chunks) {
    if (!chunk_tag_valid(c.tag) || c.tag == kTagEnd) {
      return error(ErrorCode::kInvalidArgument,
                   "cannot write a chunk tagged '" + c.tag +
                       "': tags are four ASCII letters or digits, first a letter, and 'CEND' is "
                       "written by the container itself");
    }
    const std::uint32_t limit = max_chunk_payload_bytes(c.tag);
    const std::uint64_t cap = limit > 0 ? limit : kMaxContainerBytes;
    if (c.payload.size() > cap) {
      return error(ErrorCode::kLimit,
                   "chunk '" + c.tag + "' payload of " + std::to_string(c.payload.size()) +
                       " bytes exceeds its limit of " + std::to_string(cap) + " bytes");
    }
    const auto payload_bytes = std::uint32_t(c.payload.size());
    if (c.compress && !c.payload.empty()) {
      Expected<std::vector<std::uint8_t>> z =
          zstd_compress(c.payload, std::min(zstd_level, c.max_zstd_level));
      if (!z.ok()) return z.status().with_context("chunk '" + c.tag + "'");
      // In the compact framing a compressed chunk also pays for its payload length field.
      const bool smaller =
          compact ? compact_frame_bytes(z->size(), true, payload_bytes) + z->size() <
                        compact_frame_bytes(c.payload.size(), false, 0) + c.payload.size()
                  : z->size() < c.payload.size();
      if (smaller) {
        append(c.tag, kChunkFlagZstd, *z, payload_bytes);
        continue;
      }
    }
    append(c.tag, 0, c.payload, payload_bytes);
  }
  if (compact) {
    append_compact_end(&out);
  } else {
    append_raw_chunk(&out, kTagEnd, 0, {}, 0);
  }
  if (out.size() > kMaxContainerBytes) {
    return error(ErrorCode::kLimit, "the encoded file would be " + std::to_string(out.size()) +
                                        " bytes, above the .cbrdf limit of " +
                                        std::to_string(kMaxContainerBytes) + " bytes");
  }
  return out;
}

}  // namespace cbrdf
