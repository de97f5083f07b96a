// SPDX-License-Identifier: MIT
// The version-1 chunk layer: tag rules, limits and the one validating parser, for the framing of
// 1.0-1.2 and the compact one of 1.3.
#include "cbrdf/container.h"

#include <xxhash.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <utility>

#include "byte_reader.h"
#include "zstd_util.h"

namespace cbrdf {
namespace {

bool is_upper(char c) {
  return c >= 'A' && c <= 'Z';
}
bool is_lower(char c) {
  return c >= 'a' && c <= 'z';
}
bool is_digit(char c) {
  return c >= '0' && c <= '9';
}

constexpr std::string_view kCriticalTags[] = {kTagHeader, kTagMask, kTagEnd};
// Required unless 'BASE' (version 1.3) stands in their place.
constexpr std::string_view kModelTags[] = {kTagModel, kTagMarginals};

std::string hex64(std::uint64_t v) {
  char buf[19];
  std::snprintf(buf, sizeof buf, "0x%016llx", static_cast<unsigned long long>(v));
  return buf;
}

std::string hex32(std::uint32_t v) {
  char buf[11];
  std::snprintf(buf, sizeof buf, "0x%08x", v);
  return buf;
}

std::string printable_tag(std::span<const std::uint8_t> raw) {
  std::string s;
  for (std::uint8_t b : raw) {
    if (b >= 0x20 && b < 0x7F) {
      s += char(b);
    } else {
      char buf[5];
      std::snprintf(buf, sizeof buf, "\\x%02x", b);
      s += buf;
    }
  }
  return s;
}

std::string at(std::string_view tag, std::uint64_t offset) {
  return "chunk '" + std::string(tag) + "' at offset " + std::to_string(offset);
}

// Names the usual ways a binary file is damaged in transit, so the message says what happened.
Status diagnose_signature(std::span<const std::uint8_t> bytes) {
  const auto& sig = kContainerSignature;
  const std::size_t n = std::min(bytes.size(), sig.size());
  if (bytes.empty()) return error(ErrorCode::kTruncated, "empty file (0 bytes), not a .cbrdf file");
  if (std::equal(bytes.begin(), bytes.begin() + n, sig.begin()) && n < sig.size()) {
    return error(ErrorCode::kTruncated, "file is " + std::to_string(bytes.size()) +
                                            " bytes, shorter than the 8-byte .cbrdf signature");
  }
  auto starts_with = [&](std::initializer_list<std::uint8_t> p) {
    return bytes.size() >= p.size() && std::equal(p.begin(), p.end(), bytes.begin());
  };
  if (starts_with({0x8B, 'C', 'B', 'R', '\n', 0x1A, '\n'})) {
    return error(ErrorCode::kBadSignature,
                 "bad .cbrdf signature: CR LF was converted to LF (the file was transferred in "
                 "text mode); transfer it again in binary mode");
  }
  if (starts_with({0x8B, 'C', 'B', 'R', '\r', '\r', '\n', 0x1A, '\r', '\n'})) {
    return error(ErrorCode::kBadSignature,
                 "bad .cbrdf signature: LF was converted to CR LF (the file was transferred in "
                 "text mode); transfer it again in binary mode");
  }
  if (starts_with({0x0B, 'C', 'B', 'R'})) {
    return error(ErrorCode::kBadSignature,
                 "bad .cbrdf signature: the high bit of the first byte was cleared (a 7-bit "
                 "transfer); transfer it again in binary mode");
  }
  return error(ErrorCode::kBadSignature,
               "bad signature: not a .cbrdf file (expected 8B 43 42 52 0D 0A 1A 0A, found " +
                   printable_tag(bytes.first(n)) + ")");
}

// The size limit, the signature and the version: everything before the first chunk.
Status read_preamble(std::span<const std::uint8_t> bytes, ByteReader& r, ContainerLayout* layout) {
  if (bytes.size() > kMaxContainerBytes) {
    return error(ErrorCode::kLimit, "file is " + std::to_string(bytes.size()) +
                                        " bytes, above the .cbrdf limit of " +
                                        std::to_string(kMaxContainerBytes) + " bytes");
  }
  if (bytes.size() < kContainerSignature.size() ||
      !std::equal(kContainerSignature.begin(), kContainerSignature.end(), bytes.begin())) {
    return diagnose_signature(bytes);
  }
  layout->file_bytes = bytes.size();
  CBRDF_RETURN_IF_ERROR(r.skip(kContainerSignature.size(), "signature"));
  CBRDF_RETURN_IF_ERROR(r.u16(&layout->major, "major version"));
  CBRDF_RETURN_IF_ERROR(r.u16(&layout->minor, "minor version"));
  if (layout->major > kContainerMajorVersion) {
    return error(ErrorCode::kUnsupported,
                 "file format version " + std::to_string(layout->major) + "." +
                     std::to_string(layout->minor) + " is newer than this reader (major " +
                     std::to_string(kContainerMajorVersion) + "); use a newer cbrdf");
  }
  if (layout->major == 0) {
    return error(ErrorCode::kCorrupt, "file declares major version 0, which does not exist");
  }
  return ok_status();
}

// What both framings check where a chunk should start: the file has not ended before 'CEND', and
// the chunk count stays within kMaxChunks.
Status check_chunk_start(const ByteReader& r, std::size_t chunks_so_far) {
  const std::uint64_t offset = r.offset();
  if (r.at_end()) {
    return error(ErrorCode::kTruncated, "file ends at offset " + std::to_string(offset) +
                                            " without the end chunk 'CEND' (truncated?)");
  }
  if (chunks_so_far == kMaxChunks) {
    return error(ErrorCode::kLimit, "chunk at offset " + std::to_string(offset) +
                                        " would be chunk number " + std::to_string(kMaxChunks + 1) +
                                        ", above the limit of " + std::to_string(kMaxChunks) +
                                        " chunks per file");
  }
  return ok_status();
}

// A chunk's tag (both framings): four ASCII letters or digits, and what its case says.
Status read_chunk_tag(ByteReader& r, std::uint64_t offset, ChunkInfo* info) {
  std::span<const std::uint8_t> raw_tag;
  CBRDF_RETURN_IF_ERROR(r.bytes(4, &raw_tag, "chunk tag"));
  std::string tag(raw_tag.begin(), raw_tag.end());
  if (!chunk_tag_valid(tag)) {
    return error(ErrorCode::kCorrupt, "chunk at offset " + std::to_string(offset) +
                                          " has an invalid tag '" + printable_tag(raw_tag) +
                                          "' (expected four ASCII letters or digits)");
  }
  info->critical = chunk_tag_critical(tag);
  info->known = chunk_tag_known(tag);
  info->tag = std::move(tag);
  info->offset = offset;
  return ok_status();
}

// One chunk's framing: header, stored bytes (into `stored`) and checksum, each checked against
// what is left of the file. `chunks_so_far` enforces the chunk count limit.
Status read_chunk_frame(std::span<const std::uint8_t> bytes, ByteReader& r,
                        std::size_t chunks_so_far, ChunkInfo* info,
                        std::span<const std::uint8_t>* stored) {
  const std::uint64_t offset = r.offset();
  CBRDF_RETURN_IF_ERROR(check_chunk_start(r, chunks_so_far));
  if (r.remaining() < kChunkHeaderBytes) {
    return error(ErrorCode::kTruncated, "chunk header at offset " + std::to_string(offset) +
                                            " needs " + std::to_string(kChunkHeaderBytes) +
                                            " bytes but only " + std::to_string(r.remaining()) +
                                            " are left (truncated?)");
  }
  CBRDF_RETURN_IF_ERROR(read_chunk_tag(r, offset, info));
  const std::string& tag = info->tag;
  CBRDF_RETURN_IF_ERROR(r.u32(&info->stored_bytes, "chunk length"));
  CBRDF_RETURN_IF_ERROR(r.u32(&info->flags, "chunk flags"));
  CBRDF_RETURN_IF_ERROR(r.u32(&info->payload_bytes, "chunk payload length"));
  const std::string where = at(tag, offset);
  if (std::uint64_t(info->stored_bytes) + kChunkChecksumBytes > r.remaining()) {
    return error(ErrorCode::kTruncated,
                 where + ": declared length " + std::to_string(info->stored_bytes) +
                     " plus its 8-byte checksum exceeds the " + std::to_string(r.remaining()) +
                     " bytes left in the file");
  }
  if ((info->flags & ~kChunkFlagZstd) != 0) {
    return error(ErrorCode::kCorrupt, where + ": reserved flag bits are set (flags " +
                                          hex64(info->flags) + "; only bit 0 is defined)");
  }
  info->compressed = (info->flags & kChunkFlagZstd) != 0;
  if (!info->compressed && info->payload_bytes != info->stored_bytes) {
    return error(ErrorCode::kCorrupt, where + ": uncompressed chunk declares payload length " +
                                          std::to_string(info->payload_bytes) + " but stores " +
                                          std::to_string(info->stored_bytes) + " bytes");
  }
  CBRDF_RETURN_IF_ERROR(r.bytes(info->stored_bytes, stored, "chunk payload"));
  std::uint64_t stored_sum = 0;
  CBRDF_RETURN_IF_ERROR(r.u64(&stored_sum, "chunk checksum"));
  info->frame_bytes = std::uint32_t(kChunkHeaderBytes + kChunkChecksumBytes);
  info->checksum = chunk_checksum(bytes.subspan(offset, kChunkHeaderBytes + info->stored_bytes));
  if (stored_sum != info->checksum) {
    return error(ErrorCode::kChecksum, where + ": checksum mismatch (stored " + hex64(stored_sum) +
                                           ", computed " + hex64(info->checksum) +
                                           "); the file is damaged");
  }
  return ok_status();
}

// One chunk's compact framing (minor >= 3): tag, length field (stored length x 4 + flags), payload
// length when compressed, stored bytes (into `stored`); each checked against what is left of the
// file. Nothing is verified against the file checksum yet: parse_compact does that before any
// payload is decompressed.
Status read_compact_frame(ByteReader& r, std::size_t chunks_so_far, ChunkInfo* info,
                          std::span<const std::uint8_t>* stored) {
  const std::uint64_t offset = r.offset();
  CBRDF_RETURN_IF_ERROR(check_chunk_start(r, chunks_so_far));
  if (r.remaining() < kCompactFrameMinBytes) {
    return error(ErrorCode::kTruncated,
                 "chunk header at offset " + std::to_string(offset) + " needs at least " +
                     std::to_string(kCompactFrameMinBytes) + " bytes but only " +
                     std::to_string(r.remaining()) + " are left (truncated?)");
  }
  CBRDF_RETURN_IF_ERROR(read_chunk_tag(r, offset, info));
  const std::string& tag = info->tag;
  // Built only for an error message: parsing a small file is mostly this function.
  auto where = [&] { return at(tag, offset); };
  std::uint32_t field = 0;
  if (Status st = r.varint32(&field, "length field"); !st.ok()) return st.with_context(where());
  info->stored_bytes = field >> 2;
  info->flags = field & 3u;
  if ((info->flags & ~kChunkFlagZstd) != 0) {
    return error(ErrorCode::kCorrupt, where() + ": reserved flag bit 1 is set (length field " +
                                          std::to_string(field) +
                                          "; its low two bits are the flags, only bit 0 is "
                                          "defined)");
  }
  info->compressed = (info->flags & kChunkFlagZstd) != 0;
  info->payload_bytes = info->stored_bytes;
  if (info->compressed) {
    if (Status st = r.varint32(&info->payload_bytes, "payload length"); !st.ok()) {
      return st.with_context(where());
    }
  }
  if (info->stored_bytes > r.remaining()) {
    return error(ErrorCode::kTruncated,
                 where() + ": declared length " + std::to_string(info->stored_bytes) +
                     " exceeds the " + std::to_string(r.remaining()) + " bytes left in the file");
  }
  if (tag == kTagEnd && field != 0) {
    return error(ErrorCode::kCorrupt, where() +
                                          ": the end chunk must be empty and unflagged "
                                          "(length field " +
                                          std::to_string(field) + ", expected 0)");
  }
  CBRDF_RETURN_IF_ERROR(r.bytes(info->stored_bytes, stored, "chunk payload"));
  info->frame_bytes = std::uint32_t(r.offset() - offset - info->stored_bytes);
  return ok_status();
}

// Where a chunk may stand: 'HEAD' first, no known chunk twice, no unknown critical chunk.
Status check_chunk_place(const ParsedContainer& pc, const ChunkInfo& info) {
  if (pc.layout.chunks.empty() && info.tag != kTagHeader) {
    return error(ErrorCode::kCorrupt,
                 at(info.tag, info.offset) + ": the first chunk must be 'HEAD'");
  }
  if (info.known) {
    const int first = pc.find(info.tag);
    if (first >= 0) {
      return error(ErrorCode::kCorrupt,
                   "duplicate " + std::string(info.critical ? "critical" : "ancillary") +
                       " chunk '" + info.tag + "' at offset " + std::to_string(info.offset) +
                       " (first at offset " +
                       std::to_string(pc.layout.chunks[std::size_t(first)].offset) + ")");
    }
  } else if (info.critical) {
    return error(ErrorCode::kUnsupported, "unknown critical chunk '" + info.tag + "' at offset " +
                                              std::to_string(info.offset) +
                                              ": the file needs a newer reader");
  }
  return ok_status();
}

// A known chunk's declared payload against its limit (checked as each frame is read, before
// anything of that size is allocated).
Status check_chunk_limit(const ChunkInfo& info) {
  const std::uint32_t limit = max_chunk_payload_bytes(info.tag);
  if (info.known && info.payload_bytes > limit) {
    return error(ErrorCode::kLimit, at(info.tag, info.offset) + ": payload of " +
                                        std::to_string(info.payload_bytes) +
                                        " bytes exceeds the limit of " + std::to_string(limit) +
                                        " bytes for this chunk");
  }
  return ok_status();
}

// A known chunk's payload, decompressed (its limit already checked); unknown chunks are skipped
// (empty). The end chunk must be empty and unflagged.
Expected<std::vector<std::uint8_t>> chunk_payload(const ChunkInfo& info,
                                                  std::span<const std::uint8_t> stored) {
  const std::string where = at(info.tag, info.offset);
  std::vector<std::uint8_t> payload;
  if (info.known) {
    if (info.compressed) {
      Expected<std::vector<std::uint8_t>> d = zstd_decompress_exact(stored, info.payload_bytes);
      if (!d.ok()) return d.status().with_context(where);
      payload = std::move(d.value());
    } else {
      payload.assign(stored.begin(), stored.end());
    }
  }
  if (info.tag == kTagEnd && (info.stored_bytes != 0 || info.flags != 0)) {
    return error(ErrorCode::kCorrupt, where + ": the end chunk must be empty and unflagged");
  }
  return payload;
}

// After the end chunk: nothing more in the file, and every critical chunk present.
Status check_complete(const ParsedContainer& pc, const ByteReader& r) {
  if (!r.at_end()) {
    return error(ErrorCode::kCorrupt, std::to_string(r.remaining()) +
                                          " bytes follow the end chunk at offset " +
                                          std::to_string(pc.layout.chunks.back().offset));
  }
  const std::string end_at =
      " (the end chunk is at offset " + std::to_string(pc.layout.chunks.back().offset) + ")";
  for (std::string_view tag : kCriticalTags) {
    if (pc.find(tag) < 0) {
      return error(ErrorCode::kCorrupt,
                   "missing critical chunk '" + std::string(tag) + "'" + end_at);
    }
  }
  const int base = pc.find(kTagBase);
  if (base >= 0 && pc.layout.minor < 3) {
    return error(ErrorCode::kCorrupt,
                 "chunk 'BASE' at offset " +
                     std::to_string(pc.layout.chunks[std::size_t(base)].offset) +
                     " needs container version 1.3 or later, the file is 1." +
                     std::to_string(pc.layout.minor));
  }
  // Refused here, not by the RESD reader, so that its payload (up to 40 MiB) is never decompressed.
  if (const int resd = pc.find(kTagResidual); resd >= 0 && pc.layout.minor < 2) {
    return error(ErrorCode::kCorrupt,
                 at(kTagResidual, pc.layout.chunks[std::size_t(resd)].offset) +
                     ": 'RESD' needs container version 1.2 or later, the file is 1." +
                     std::to_string(pc.layout.minor));
  }
  for (std::string_view tag : kModelTags) {
    const int i = pc.find(tag);
    if (base < 0 && i < 0) {
      return error(ErrorCode::kCorrupt,
                   "missing critical chunk '" + std::string(tag) + "'" + end_at);
    }
    if (base >= 0 && i >= 0) {
      return error(ErrorCode::kCorrupt,
                   "chunk '" + std::string(tag) + "' at offset " +
                       std::to_string(pc.layout.chunks[std::size_t(i)].offset) +
                       " in a file with 'BASE', which holds the model and marginals in its place");
    }
  }
  return ok_status();
}

}  // namespace

bool chunk_tag_valid(std::string_view tag) {
  if (tag.size() != 4) return false;
  if (!is_upper(tag[0]) && !is_lower(tag[0])) return false;
  for (std::size_t i = 1; i < 4; ++i) {
    if (!is_upper(tag[i]) && !is_digit(tag[i])) return false;
  }
  return true;
}

bool chunk_tag_critical(std::string_view tag) {
  return !tag.empty() && is_upper(tag[0]);
}

bool chunk_tag_known(std::string_view tag) {
  return max_chunk_payload_bytes(tag) > 0 || tag == kTagEnd;
}

std::uint32_t max_chunk_payload_bytes(std::string_view tag) {
  if (tag == kTagHeader) return 256;
  if (tag == kTagModel) return 64u << 10;
  if (tag == kTagMarginals) return 2u << 20;  // 1 MiB in version 1.0; mixtures need more
  if (tag == kTagBase) return 4u << 20;       // MODL's and MARG's limits together, rounded up
  if (tag == kTagMask) return 36u << 20;
  if (tag == kTagResidual) return 40u << 20;  // mode 1 holds a whole exact table
  if (tag == kTagMetadata) return 64u << 10;
  return 0;  // the end chunk is empty; unknown chunks are never decompressed
}

int ParsedContainer::find(std::string_view tag) const {
  for (std::size_t i = 0; i < layout.chunks.size(); ++i) {
    if (layout.chunks[i].tag == tag) return int(i);
  }
  return -1;
}

std::uint64_t chunk_checksum(std::span<const std::uint8_t> header_and_stored) {
  return XXH64(header_and_stored.data(), header_and_stored.size(), 0);
}

std::uint32_t file_checksum(std::span<const std::uint8_t> bytes_before_checksum) {
  return std::uint32_t(XXH64(bytes_before_checksum.data(), bytes_before_checksum.size(), 0));
}

namespace {

// The last stage of both framings: the set of chunks is checked before any payload is
// decompressed (each chunk's limit was checked with its frame), so that a file whose
// chunks could never decode together (BASE beside MODL and MARG, a missing critical chunk)
// allocates nothing of their declared sizes (spec 7: else a file with every chunk at its maximum
// has the parser allocate all of them before refusing it).
Expected<ParsedContainer> decompress_checked(ParsedContainer pc,
                                             std::span<const std::span<const std::uint8_t>> stored,
                                             const ByteReader& r) {
  CBRDF_RETURN_IF_ERROR(check_complete(pc, r));
  pc.payloads.reserve(pc.layout.chunks.size());
  for (std::size_t i = 0; i < pc.layout.chunks.size(); ++i) {
    CBRDF_ASSIGN_OR_RETURN(std::vector<std::uint8_t> payload,
                           chunk_payload(pc.layout.chunks[i], stored[i]));
    pc.payloads.push_back(std::move(payload));
  }
  return pc;
}

// The compact framing in two passes: every frame and the file checksum first, so that damage
// anywhere is caught before any byte reaches the decompressor; then each chunk's place, limit
// and payload, as for the older framing.
Expected<ParsedContainer> parse_compact(std::span<const std::uint8_t> bytes, ByteReader& r,
                                        ParsedContainer pc) {
  std::vector<ChunkInfo> infos;
  std::vector<std::span<const std::uint8_t>> stored;
  infos.reserve(8);  // a file has 5-7 chunks
  stored.reserve(8);
  while (infos.empty() || infos.back().tag != kTagEnd) {
    ChunkInfo info;
    std::span<const std::uint8_t> s;
    CBRDF_RETURN_IF_ERROR(read_compact_frame(r, infos.size(), &info, &s));
    infos.push_back(std::move(info));
    stored.push_back(s);
  }
  ChunkInfo& end = infos.back();
  const std::uint64_t sum_at = r.offset();
  if (r.remaining() < kFileChecksumBytes) {
    return error(ErrorCode::kTruncated,
                 "the file checksum after the end chunk at offset " + std::to_string(end.offset) +
                     " needs " + std::to_string(kFileChecksumBytes) + " bytes but only " +
                     std::to_string(r.remaining()) + " are left (truncated?)");
  }
  std::uint32_t stored_sum = 0;
  CBRDF_RETURN_IF_ERROR(r.u32(&stored_sum, "file checksum"));
  const std::uint32_t sum = file_checksum(bytes.first(std::size_t(sum_at)));
  if (stored_sum != sum) {
    return error(ErrorCode::kChecksum, "file checksum at offset " + std::to_string(sum_at) +
                                           " does not match (stored " + hex32(stored_sum) +
                                           ", computed " + hex32(sum) + " over bytes 0-" +
                                           std::to_string(sum_at - 1) + "); the file is damaged");
  }
  end.checksum = stored_sum;
  end.frame_bytes += std::uint32_t(kFileChecksumBytes);
  for (ChunkInfo& info : infos) {
    CBRDF_RETURN_IF_ERROR(check_chunk_place(pc, info));
    CBRDF_RETURN_IF_ERROR(check_chunk_limit(info));
    pc.layout.chunks.push_back(std::move(info));
  }
  return decompress_checked(std::move(pc), stored, r);
}

}  // namespace

Expected<ContainerLayout> read_container_version(std::span<const std::uint8_t> bytes) {
  ContainerLayout layout;
  ByteReader r(bytes);
  CBRDF_RETURN_IF_ERROR(read_preamble(bytes, r, &layout));
  return layout;
}

Expected<ParsedContainer> parse_container(std::span<const std::uint8_t> bytes) {
  ParsedContainer pc;
  ByteReader r(bytes);
  CBRDF_RETURN_IF_ERROR(read_preamble(bytes, r, &pc.layout));
  if (uses_compact_framing(pc.layout.minor)) return parse_compact(bytes, r, std::move(pc));
  std::vector<std::span<const std::uint8_t>> stored;
  bool ended = false;
  while (!ended) {
    ChunkInfo info;
    std::span<const std::uint8_t> s;
    CBRDF_RETURN_IF_ERROR(read_chunk_frame(bytes, r, pc.layout.chunks.size(), &info, &s));
    CBRDF_RETURN_IF_ERROR(check_chunk_place(pc, info));
    CBRDF_RETURN_IF_ERROR(check_chunk_limit(info));
    ended = info.tag == kTagEnd;
    pc.layout.chunks.push_back(std::move(info));
    stored.push_back(s);
  }
  return decompress_checked(std::move(pc), stored, r);
}

}  // namespace cbrdf
