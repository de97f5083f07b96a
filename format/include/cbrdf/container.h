// SPDX-License-Identifier: MIT
/// @file
/// The .cbrdf chunk layer (container version 1.x): signature, version, chunks with checksums and
/// optional zstd compression (from 1.3 in a compact framing with one checksum for the file), and
/// the one validating parser used by decode, `cbrdf info`, the fuzzers and the tests. What the
/// payloads mean is the codec's business (cbrdf/codec.h); this layer knows only which tags version
/// 1 defines and how large each may be. spec/container.md is the normative description.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cbrdf/status.h"

namespace cbrdf {

/// 0x8B: high bit set catches 7-bit transfers and marks the file binary; "CBR" names it; CR LF and
/// LF catch line-ending conversion either way; 0x1A stops `type` on DOS-like systems.
inline constexpr std::array<std::uint8_t, 8> kContainerSignature = {0x8B, 'C',  'B',  'R',
                                                                    '\r', '\n', 0x1A, '\n'};
/// The major version this library reads and writes; a reader refuses any other.
inline constexpr std::uint16_t kContainerMajorVersion = 1;
/// 1.1 added mixtures (several components per slice and channel), 1.2 the residual layer (the
/// critical chunk 'RESD'); the writer writes the lowest version that holds the model, so that
/// files without them stay readable by older readers.
/// 1.3 the compact coding ('BASE' in place of 'MODL' and 'MARG', a 2-byte 'HEAD'), written only
/// where it is smaller.
inline constexpr std::uint16_t kContainerMinorVersion = 3;

inline constexpr std::size_t kContainerHeaderBytes = 12;  ///< signature, u16 major, u16 minor
/** The framing of minor versions 0-2 (spec section 2.1). */
///@{
inline constexpr std::size_t kChunkHeaderBytes = 16;  ///< tag, stored length, flags, payload length
inline constexpr std::size_t kChunkChecksumBytes = 8;  ///< XXH64 of header + stored bytes
///@}
/** The compact framing of minor versions 3 and later (spec section 2.2): tag, a varint holding the
    stored length and the flags, the payload length only when compressed, and one 32-bit checksum
    of the whole file after the end chunk. */
///@{
inline constexpr std::uint16_t kCompactFramingMinor = 3;  ///< the first minor version using it
inline constexpr std::size_t kCompactFrameMinBytes = 5;   ///< tag and a 1-byte length field
inline constexpr std::size_t kFileChecksumBytes = 4;      ///< after the end chunk
/// Whether files of this minor version use the compact framing.
constexpr bool uses_compact_framing(std::uint16_t minor) {
  return minor >= kCompactFramingMinor;
}
///@}
inline constexpr std::uint64_t kMaxContainerBytes = std::uint64_t{64} << 20;  ///< 64 MiB
/// Bounds the parser's bookkeeping: a file of tiny unknown chunks cannot make it allocate more
/// than a few hundred kilobytes of chunk descriptions.
inline constexpr std::size_t kMaxChunks = 1024;

/// Chunk flag bits; every other bit is reserved and must be zero (the compact framing has two
/// flag bits, the low bits of its length field).
inline constexpr std::uint32_t kChunkFlagZstd = 1u;  ///< the stored bytes are one zstd frame

/** The tags of version 1. A tag whose first letter is upper case is critical (PNG's convention):
    a reader that does not know it must refuse the file; a lower-case first letter marks an
    ancillary chunk that unknowing readers skip. */
///@{
inline constexpr std::string_view kTagHeader = "HEAD";
inline constexpr std::string_view kTagModel = "MODL";
inline constexpr std::string_view kTagMarginals = "MARG";
inline constexpr std::string_view kTagMask = "MASK";
inline constexpr std::string_view kTagResidual = "RESD";  ///< optional; version 1.2
/// Version 1.3: the model and its coded marginal tables, in place of MODL and MARG.
inline constexpr std::string_view kTagBase = "BASE";
inline constexpr std::string_view kTagMetadata = "mETA";
inline constexpr std::string_view kTagEnd = "CEND";
///@}

bool chunk_tag_valid(std::string_view tag);  ///< four ASCII letters or digits, first a letter
/// Whether a reader must know the tag (first letter upper case).
bool chunk_tag_critical(std::string_view tag);
bool chunk_tag_known(std::string_view tag);  ///< Whether the tag is one of version 1's.
/// Largest payload (after decompression) a version-1 reader accepts for a known tag; 0 otherwise.
std::uint32_t max_chunk_payload_bytes(std::string_view tag);

/// One chunk as found in a file (parse_container).
struct ChunkInfo {
  std::string tag;                  ///< four characters
  std::uint64_t offset = 0;         ///< of the chunk's tag in the file
  std::uint32_t flags = 0;          ///< kChunkFlag* bits
  std::uint32_t stored_bytes = 0;   ///< as written in the file
  std::uint32_t payload_bytes = 0;  ///< after decompression
  /// As stored and verified by the parser: the chunk's XXH64 (minor 0-2); in the compact framing
  /// 0, and on the end chunk the 32-bit file checksum.
  std::uint64_t checksum = 0;
  bool critical = false;    ///< chunk_tag_critical(tag)
  bool compressed = false;  ///< kChunkFlagZstd set
  bool known = false;       ///< false: an ancillary chunk this reader skipped
  /// Bytes of framing: everything of the chunk but its stored bytes (the compact end chunk counts
  /// the file checksum), so the next chunk starts at offset + frame_bytes + stored_bytes.
  std::uint32_t frame_bytes = 0;
};

/// A container's version and chunks, as read.
struct ContainerLayout {
  /** The container version (major.minor). */
  ///@{
  std::uint16_t major = 0;
  std::uint16_t minor = 0;
  ///@}
  std::uint64_t file_bytes = 0;   ///< the whole file
  std::vector<ChunkInfo> chunks;  ///< file order, the end chunk included
};

/// A validated container: its layout and the decompressed payloads of known chunks.
struct ParsedContainer {
  ContainerLayout layout;  ///< version and chunks
  /// Decompressed payloads parallel to layout.chunks (empty for skipped unknown chunks).
  std::vector<std::vector<std::uint8_t>> payloads;
  /// Index of the chunk with this tag in layout.chunks, or -1 when absent.
  int find(std::string_view tag) const;
};

/// Validates the whole container: signature (with a diagnosis of text-mode damage), version,
/// every chunk's bounds, flags, checksum and size limits, the set and order of critical chunks,
/// and nothing after the end chunk. Decompresses the known chunks.
Expected<ParsedContainer> parse_container(std::span<const std::uint8_t> bytes);

/// The version a file declares, from its 12-byte header alone (the size limit, the signature and
/// the version checked as parse_container() checks them; no chunk is read, so chunks stays
/// empty): for code that adds to a file it wrote and must know which codings the
/// file may hold (e.g. RESD mode 4 only in a file of minor version 3 or more).
Expected<ContainerLayout> read_container_version(std::span<const std::uint8_t> bytes);

/// XXH64 (seed 0) of a chunk's 16 header bytes followed by its stored bytes.
std::uint64_t chunk_checksum(std::span<const std::uint8_t> header_and_stored);
/// The compact framing's file checksum: the low 32 bits of XXH64 (seed 0) of every byte of the
/// file before it (zstd's content checksum is the same construction).
std::uint32_t file_checksum(std::span<const std::uint8_t> bytes_before_checksum);

/// Appends one chunk exactly as given (no compression, no checks): the low-level writer, also
/// used by tests and fuzz seeds to build files that a normal writer would never produce.
void append_raw_chunk(std::vector<std::uint8_t>* out, std::string_view tag, std::uint32_t flags,
                      std::span<const std::uint8_t> stored, std::uint32_t payload_bytes);
/// The compact framing's counterpart of append_raw_chunk: tag, varint (stored length x 4 + the low
/// two bits of `flags`), varint payload length when bit 0 is set. Also writes what a normal writer
/// would not (reserved bit 1, any payload length).
void append_compact_chunk(std::vector<std::uint8_t>* out, std::string_view tag, std::uint32_t flags,
                          std::span<const std::uint8_t> stored, std::uint32_t payload_bytes);
/// The compact framing's end: the chunk 'CEND' (length field 0) and the file checksum of all of
/// `*out` up to it.
void append_compact_end(std::vector<std::uint8_t>* out);
/// The 12-byte file header: signature and version.
std::vector<std::uint8_t> container_file_header(std::uint16_t major = kContainerMajorVersion,
                                                std::uint16_t minor = 0);

/// One chunk for write_container().
struct ChunkToWrite {
  std::string tag;                    ///< four characters (chunk_tag_valid)
  std::vector<std::uint8_t> payload;  ///< the uncompressed payload
  bool compress = true;               ///< zstd, kept only when it is smaller than the payload
  int max_zstd_level = 22;  ///< caps write_container's level for this chunk (large payloads)
};

/// Writes header (version 1.minor), chunks in the given order and the end chunk, in the framing of
/// that minor version (uses_compact_framing). Refuses invalid
/// tags and payloads above their limits (kInvalidArgument / kLimit), so that whatever it writes
/// parses.
Expected<std::vector<std::uint8_t>> write_container(std::span<const ChunkToWrite> chunks,
                                                    int zstd_level, std::uint16_t minor = 0);

}  // namespace cbrdf
