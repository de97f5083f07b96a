// SPDX-License-Identifier: MIT
// The container writer: the file header, chunks (zstd where it pays) and the end chunk.
#include <algorithm>
#include <string>

#include "byte_writer.h"
#include "cbrdf/container.h"
#include "zstd_util.h"

namespace cbrdf {

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

Expected<std::vector<std::uint8_t>> write_container(std::span<const ChunkToWrite> chunks,
                                                    int zstd_level, std::uint16_t minor) {
  if (minor > kContainerMinorVersion) {
    return error(ErrorCode::kInvalidArgument, "cannot write minor version " +
                                                  std::to_string(minor) + ": this writer knows 1." +
                                                  std::to_string(kContainerMinorVersion));
  }
  std::vector<std::uint8_t> out = container_file_header(kContainerMajorVersion, minor);
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
      if (z->size() < c.payload.size()) {
        append_raw_chunk(&out, c.tag, kChunkFlagZstd, *z, payload_bytes);
        continue;
      }
    }
    append_raw_chunk(&out, c.tag, 0, c.payload, payload_bytes);
  }
  append_raw_chunk(&out, kTagEnd, 0, {}, 0);
  if (out.size() > kMaxContainerBytes) {
    return error(ErrorCode::kLimit, "the encoded file would be " + std::to_string(out.size()) +
                                        " bytes, above the .cbrdf limit of " +
                                        std::to_string(kMaxContainerBytes) + " bytes");
  }
  return out;
}

}  // namespace cbrdf
