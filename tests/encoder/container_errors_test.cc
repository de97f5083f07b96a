// SPDX-License-Identifier: MIT
// Malformed .cbrdf files: each case must fail with a stated ErrorCode and a message that says
// what is wrong and where (chunk tag and byte offset).
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <string>

#include "byte_reader.h"
#include "cbrdf/codec.h"
#include "cbrdf/container.h"
#include "cbrdf/container_writer.h"
#include "coding_1_2.h"
#include "refused.h"
#include "synthetic_model.h"
#include "zstd_util.h"

namespace cbrdf {
namespace {

using Bytes = std::vector<std::uint8_t>;

Bytes encode(const Model& m, int bits = 6) {
  ContainerSettings s = testing::coding_1_2();
  s.bits = bits;
  s.zstd_level = 3;
  s.source_name = "errors";
  Expected<Bytes> b = encode_model(m, s);
  EXPECT_TRUE(b.ok()) << b.status().message();
  return b.ok() ? *b : Bytes{};
}

const Bytes& small_file() {  // one slice: about 700 bytes
  static const Bytes b = encode(testing::make_model({0, 90}, false, 1));
  return b;
}

// Version 1.1, one slice: channel R has 1 component, G 2 and B 3. MODL: slice end (1 byte), three
// 17-byte first components (to offset 52), counts 0, 1, 2 at 52..54, then three 17-byte
// components from 55 (G's, then B's two).
const Bytes& mixture_file() {
  static const Bytes b = encode(testing::make_mixture_model({0, 90}, 3, 5));
  return b;
}

const Bytes& six_slice_file() {
  static const Bytes b = encode(testing::make_model(testing::six_slices(), true, 2), 10);
  return b;
}

ContainerLayout layout_of(const Bytes& b) {
  Expected<ParsedContainer> pc = parse_container(b);
  EXPECT_TRUE(pc.ok()) << pc.status().message();
  return pc.ok() ? pc->layout : ContainerLayout{};
}

const ChunkInfo& chunk(const ContainerLayout& l, std::string_view tag) {
  for (const ChunkInfo& c : l.chunks) {
    if (c.tag == tag) return c;
  }
  ADD_FAILURE() << "no chunk " << tag;
  return l.chunks.front();
}

void expect_error(const Bytes& b, ErrorCode code, const std::string& needle) {
  testing::expect_refused(b, code, needle);
  // inspect_container runs the same validation.
  Expected<ContainerInfo> info = inspect_container(b);
  ASSERT_FALSE(info.ok());
  EXPECT_EQ(info.status().message(), decode_model(b).status().message());
}

// Rewrites the compact framing's file checksum (the last 4 bytes) after an edit.
void seal(Bytes* b) {
  const std::uint32_t sum = file_checksum(std::span<const std::uint8_t>(*b).first(b->size() - 4));
  for (int i = 0; i < 4; ++i) (*b)[b->size() - 4 + std::size_t(i)] = std::uint8_t(sum >> (8 * i));
}

// Re-writes a file chunk by chunk (valid checksums) after `edit` changes the list of chunks.
// The version is the file's own unless `minor` is given.
Bytes rebuild(const Bytes& file, const std::function<void(std::vector<ChunkToWrite>*)>& edit,
              int minor = -1) {
  Expected<ParsedContainer> pc = parse_container(file);
  EXPECT_TRUE(pc.ok());
  std::vector<ChunkToWrite> chunks;
  for (std::size_t i = 0; i + 1 < pc->layout.chunks.size(); ++i) {
    chunks.push_back({pc->layout.chunks[i].tag, pc->payloads[i], true});
  }
  edit(&chunks);
  const int m = minor >= 0 ? minor : int(pc->layout.minor);
  const bool compact = uses_compact_framing(std::uint16_t(m));
  // Written in the framing of the version it is labelled with.
  Expected<Bytes> out = write_container(chunks, 3, compact ? kCompactFramingMinor : 0);
  EXPECT_TRUE(out.ok()) << out.status().message();
  Bytes b = *out;
  b[10] = std::uint8_t(m);
  b[11] = std::uint8_t(m >> 8);
  if (compact) seal(&b);
  return b;
}

Bytes edit_payload(const Bytes& file, std::string_view tag, const std::function<void(Bytes*)>& edit,
                   int minor = -1) {
  return rebuild(
      file,
      [&](std::vector<ChunkToWrite>* chunks) {
        for (ChunkToWrite& c : *chunks) {
          if (c.tag == tag) edit(&c.payload);
        }
      },
      minor);
}

void put_u64(Bytes* b, std::size_t at, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) (*b)[at + std::size_t(i)] = std::uint8_t(v >> (8 * i));
}
void put_u32(Bytes* b, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) (*b)[at + std::size_t(i)] = std::uint8_t(v >> (8 * i));
}

// Recomputes the checksum of the chunk at `offset` after its header or stored bytes changed.
void fix_checksum(Bytes* b, std::size_t offset) {
  std::uint32_t stored = 0;
  ByteReader r(std::span<const std::uint8_t>(*b).subspan(offset + 4, 4));
  ASSERT_TRUE(r.u32(&stored, "len").ok());
  const std::size_t end = offset + kChunkHeaderBytes + stored;
  put_u64(b, end, chunk_checksum(std::span<const std::uint8_t>(*b).subspan(offset, end - offset)));
}

std::string at(const ContainerLayout& l, std::string_view tag) {
  return "chunk '" + std::string(tag) + "' at offset " + std::to_string(chunk(l, tag).offset);
}

TEST(ContainerErrors, EmptyFile) {
  expect_error({}, ErrorCode::kTruncated, "empty file");
}

TEST(ContainerErrors, WrongSignature) {
  const std::string png = "\x89PNG\r\n\x1a\n0000000000000000";
  expect_error(Bytes(png.begin(), png.end()), ErrorCode::kBadSignature, "not a .cbrdf file");
}

TEST(ContainerErrors, ShorterThanTheSignature) {
  expect_error(Bytes(small_file().begin(), small_file().begin() + 5), ErrorCode::kTruncated,
               "shorter than the 8-byte .cbrdf signature");
}

TEST(ContainerErrors, TextModeDamageCrLfToLf) {
  Bytes damaged;
  const Bytes& f = small_file();
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (f[i] == '\r' && i + 1 < f.size() && f[i + 1] == '\n') continue;
    damaged.push_back(f[i]);
  }
  expect_error(damaged, ErrorCode::kBadSignature, "CR LF was converted to LF");
}

TEST(ContainerErrors, TextModeDamageLfToCrLf) {
  Bytes damaged;
  for (std::uint8_t c : small_file()) {
    if (c == '\n') damaged.push_back('\r');
    damaged.push_back(c);
  }
  expect_error(damaged, ErrorCode::kBadSignature, "LF was converted to CR LF");
}

TEST(ContainerErrors, SevenBitTransfer) {
  Bytes damaged = small_file();
  for (std::uint8_t& c : damaged) c &= 0x7F;
  expect_error(damaged, ErrorCode::kBadSignature, "7-bit transfer");
}

TEST(ContainerErrors, NewerMajorVersion) {
  Bytes b = small_file();
  b[8] = 2;
  expect_error(b, ErrorCode::kUnsupported, "version 2.0 is newer than this reader");
}

TEST(ContainerErrors, MajorVersionZero) {
  Bytes b = small_file();
  b[8] = 0;
  expect_error(b, ErrorCode::kCorrupt, "major version 0");
}

TEST(ContainerErrors, TruncatedAtEveryChunkBoundary) {
  const Bytes& f = six_slice_file();
  const ContainerLayout l = layout_of(f);
  for (const ChunkInfo& c : l.chunks) {
    SCOPED_TRACE(c.tag);
    expect_error(Bytes(f.begin(), f.begin() + std::ptrdiff_t(c.offset)), ErrorCode::kTruncated,
                 "file ends at offset " + std::to_string(c.offset) + " without the end chunk");
  }
}

TEST(ContainerErrors, TruncatedAtEveryByte) {
  const Bytes& f = small_file();
  ASSERT_LT(f.size(), 2000u);
  for (std::size_t n = 0; n < f.size(); ++n) {
    Expected<Model> m = decode_model(std::span(f).first(n));
    ASSERT_FALSE(m.ok()) << n;
    ASSERT_EQ(m.status().code(), ErrorCode::kTruncated) << n << ": " << m.status().message();
  }
  EXPECT_TRUE(decode_model(f).ok());
}

TEST(ContainerErrors, ChecksumMismatch) {
  const ContainerLayout l = layout_of(small_file());
  Bytes b = small_file();
  b[chunk(l, "MARG").offset + kChunkHeaderBytes + 3] ^= 0x01;
  expect_error(b, ErrorCode::kChecksum, at(l, "MARG") + ": checksum mismatch");
}

TEST(ContainerErrors, EverySingleByteCorruptionIsDetected) {
  const Bytes& f = small_file();
  for (std::size_t i = kContainerHeaderBytes; i < f.size(); ++i) {
    Bytes b = f;
    b[i] ^= 0x10;
    ASSERT_FALSE(decode_model(b).ok()) << "flipping a bit of byte " << i << " went unnoticed";
  }
}

TEST(ContainerErrors, LengthPastTheEnd) {
  const ContainerLayout l = layout_of(small_file());
  Bytes b = small_file();
  const std::size_t off = chunk(l, "MARG").offset;
  put_u32(&b, off + 4, 99999);
  const std::size_t left = b.size() - off - kChunkHeaderBytes;
  expect_error(b, ErrorCode::kTruncated,
               at(l, "MARG") + ": declared length 99999 plus its 8-byte checksum exceeds the " +
                   std::to_string(left) + " bytes left in the file");
}

TEST(ContainerErrors, DuplicateCriticalChunk) {
  const Bytes b = rebuild(small_file(), [](std::vector<ChunkToWrite>* c) {
    c->insert(c->begin() + 2, (*c)[1]);  // a second MODL
  });
  const ContainerLayout l = [&] {  // the second MODL's offset, from the file itself
    ContainerLayout x;
    std::size_t off = kContainerHeaderBytes;
    while (off < b.size()) {
      std::uint32_t len = 0;
      ByteReader h(std::span<const std::uint8_t>(b).subspan(off + 4, 4));
      EXPECT_TRUE(h.u32(&len, "len").ok());
      ChunkInfo ci;
      ci.tag = std::string(b.begin() + std::ptrdiff_t(off), b.begin() + std::ptrdiff_t(off + 4));
      ci.offset = off;
      x.chunks.push_back(ci);
      off += kChunkHeaderBytes + len + kChunkChecksumBytes;
    }
    return x;
  }();
  ASSERT_EQ(l.chunks[2].tag, "MODL");
  expect_error(b, ErrorCode::kCorrupt,
               "duplicate critical chunk 'MODL' at offset " + std::to_string(l.chunks[2].offset) +
                   " (first at offset " + std::to_string(l.chunks[1].offset) + ")");
}

TEST(ContainerErrors, DuplicateAncillaryMetadataChunk) {
  const Bytes b =
      rebuild(small_file(), [](std::vector<ChunkToWrite>* c) { c->push_back(c->back()); });
  expect_error(b, ErrorCode::kCorrupt, "duplicate ancillary chunk 'mETA'");
}

TEST(ContainerErrors, MissingCriticalChunk) {
  const Bytes b = rebuild(small_file(), [](std::vector<ChunkToWrite>* c) {
    std::erase_if(*c, [](const ChunkToWrite& x) { return x.tag == "MASK"; });
  });
  expect_error(b, ErrorCode::kCorrupt, "missing critical chunk 'MASK'");
}

TEST(ContainerErrors, FirstChunkMustBeHeader) {
  const Bytes b =
      rebuild(small_file(), [](std::vector<ChunkToWrite>* c) { std::swap((*c)[0], (*c)[1]); });
  expect_error(b, ErrorCode::kCorrupt, "chunk 'MODL' at offset 12: the first chunk must be 'HEAD'");
}

TEST(ContainerErrors, UnknownCriticalChunk) {
  const Bytes b = rebuild(small_file(), [](std::vector<ChunkToWrite>* c) {
    c->insert(c->begin() + 1, ChunkToWrite{"XTRA", {1, 2, 3}, false});
  });
  // Right after HEAD, the first chunk.
  const std::size_t off = kContainerHeaderBytes + kChunkHeaderBytes +
                          layout_of(small_file()).chunks[0].stored_bytes + kChunkChecksumBytes;
  expect_error(b, ErrorCode::kUnsupported,
               "unknown critical chunk 'XTRA' at offset " + std::to_string(off) +
                   ": the file needs a newer reader");
}

TEST(ContainerErrors, UnknownAncillaryChunkIsSkipped) {
  const Bytes b = rebuild(small_file(), [](std::vector<ChunkToWrite>* c) {
    c->insert(c->begin() + 2, ChunkToWrite{"xTRA", Bytes(500, 9), true});
  });
  Expected<Model> with = decode_model(b);
  Expected<Model> without = decode_model(small_file());
  ASSERT_TRUE(with.ok()) << with.status().message();
  ASSERT_TRUE(without.ok());
  ASSERT_EQ(with->slices.size(), without->slices.size());
  EXPECT_EQ(with->slices[0].channel[1].pdf_h, without->slices[0].channel[1].pdf_h);
  EXPECT_EQ(with->not_measured.bits, without->not_measured.bits);
  Expected<ContainerInfo> info = inspect_container(b);
  ASSERT_TRUE(info.ok());
  EXPECT_EQ(info->layout.chunks[2].tag, "xTRA");
  EXPECT_FALSE(info->layout.chunks[2].known);
}

// MODL payload: one end byte per slice, then per slice and channel u8 family, f64 theta, f64 K.
constexpr std::size_t kModlParamsAt = 1;  // one slice in small_file()

TEST(ContainerErrors, NaNParameter) {
  const Bytes b = edit_payload(small_file(), "MODL", [](Bytes* p) {
    put_u64(p, kModlParamsAt + 1,
            std::bit_cast<std::uint64_t>(std::numeric_limits<double>::quiet_NaN()));
  });
  expect_error(b, ErrorCode::kNumeric,
               at(layout_of(b), "MODL") + ": slice 0 channel R: parameter nan is not finite");
}

TEST(ContainerErrors, OutOfDomainParameter) {
  const Bytes b = edit_payload(small_file(), "MODL", [](Bytes* p) {
    (*p)[kModlParamsAt] = std::uint8_t(CopulaFamily::kGumbel);
    put_u64(p, kModlParamsAt + 1, std::bit_cast<std::uint64_t>(0.5));
  });
  expect_error(
      b, ErrorCode::kNumeric,
      "slice 0 channel R: parameter 0.5 is outside the gumbel domain a file may hold, [1, 20]");
}

TEST(ContainerErrors, FrankParameterAboveLn2) {
  const Bytes b = edit_payload(small_file(), "MODL", [](Bytes* p) {
    (*p)[kModlParamsAt] = std::uint8_t(CopulaFamily::kFrank);
    put_u64(p, kModlParamsAt + 1, std::bit_cast<std::uint64_t>(0.7));
  });
  expect_error(b, ErrorCode::kNumeric,
               "parameter 0.69999999999999996 is outside the frank domain a file may hold, [-200, "
               "0.69314718055994529]");
}

TEST(ContainerErrors, UnknownFamily) {
  const Bytes b =
      edit_payload(small_file(), "MODL", [](Bytes* p) { (*p)[kModlParamsAt + 17] = 9; });
  expect_error(b, ErrorCode::kCorrupt, "slice 0 channel G: unknown copula family 9");
}

TEST(ContainerErrors, NegativeOrInfiniteScale) {
  for (double k : {-1.0, std::numeric_limits<double>::infinity()}) {
    const Bytes b = edit_payload(small_file(), "MODL", [&](Bytes* p) {
      put_u64(p, kModlParamsAt + 9, std::bit_cast<std::uint64_t>(k));
    });
    expect_error(b, ErrorCode::kNumeric, "scale K");
  }
}

TEST(ContainerErrors, SlicesNotCoveringTheGrid) {
  const Bytes b = edit_payload(small_file(), "MODL", [](Bytes* p) { (*p)[0] = 80; });
  expect_error(b, ErrorCode::kCorrupt, "slice 0 ends at theta_d bin 80");
}

TEST(ContainerErrors, BitsOutOfRange) {
  for (std::uint8_t bits : {5, 17}) {
    const Bytes b = edit_payload(small_file(), "MARG", [&](Bytes* p) { (*p)[0] = bits; });
    expect_error(
        b, ErrorCode::kCorrupt,
        at(layout_of(b), "MARG") + ": bits per code " + std::to_string(bits) + " is outside 6..16");
  }
}

TEST(ContainerErrors, MarginalCodeBelowZero) {
  // MARG: u8 bits, u8 0, u16 tables, tables x (f32 lo, f32 hi), then the residual varints.
  const Bytes b = edit_payload(small_file(), "MARG", [](Bytes* p) { (*p)[4 + 9 * 8] = 0x01; });
  expect_error(
      b, ErrorCode::kCorrupt,
      "slice 0 channel R theta_h table: residual at payload offset 76 gives code -1 outside 0..63");
}

TEST(ContainerErrors, MarginalRangeNotFinite) {
  const Bytes b = edit_payload(small_file(), "MARG", [](Bytes* p) {
    put_u32(p, 4, std::bit_cast<std::uint32_t>(std::numeric_limits<float>::infinity()));
  });
  expect_error(b, ErrorCode::kNumeric, "slice 0 channel R theta_h table: log-mass range");
}

TEST(ContainerErrors, DecompressedSizeOverItsBound) {
  // A 4 MiB zstd bomb (a few dozen bytes) where MARG may hold at most 2 MiB: refused before
  // anything is allocated for it.
  const Bytes zeros(4u << 20, 0);
  Expected<Bytes> bomb = zstd_compress(zeros, 3);
  ASSERT_TRUE(bomb.ok());
  ASSERT_LT(bomb->size(), 1000u);
  const ContainerLayout l = layout_of(small_file());
  Bytes b = container_file_header();
  for (const ChunkInfo& c : l.chunks) {
    const auto begin = small_file().begin() + std::ptrdiff_t(c.offset);
    if (c.tag == "MARG") {
      append_raw_chunk(&b, "MARG", kChunkFlagZstd, *bomb, std::uint32_t(zeros.size()));
    } else {
      b.insert(b.end(), begin,
               begin + std::ptrdiff_t(kChunkHeaderBytes + c.stored_bytes + kChunkChecksumBytes));
    }
  }
  expect_error(b, ErrorCode::kLimit,
               at(l, "MARG") + ": payload of 4194304 bytes exceeds the limit of 2097152 bytes");
}

TEST(ContainerErrors, FrameContentSizeDisagreesWithChunk) {
  const Bytes payload(5000, 3);
  Expected<Bytes> z = zstd_compress(payload, 3);
  ASSERT_TRUE(z.ok());
  const ContainerLayout l = layout_of(small_file());
  Bytes b = container_file_header();
  for (const ChunkInfo& c : l.chunks) {
    const auto begin = small_file().begin() + std::ptrdiff_t(c.offset);
    if (c.tag == "MARG") {
      append_raw_chunk(&b, "MARG", kChunkFlagZstd, *z, 4000);
    } else {
      b.insert(b.end(), begin,
               begin + std::ptrdiff_t(kChunkHeaderBytes + c.stored_bytes + kChunkChecksumBytes));
    }
  }
  expect_error(b, ErrorCode::kCorrupt,
               at(l, "MARG") +
                   ": the zstd frame declares 5000 bytes of content but the chunk declares 4000");
}

TEST(ContainerErrors, ReservedFlagBits) {
  const ContainerLayout l = layout_of(small_file());
  Bytes b = small_file();
  b[chunk(l, "HEAD").offset + 8] |= 0x02;
  fix_checksum(&b, chunk(l, "HEAD").offset);
  expect_error(b, ErrorCode::kCorrupt, at(l, "HEAD") + ": reserved flag bits are set");
}

TEST(ContainerErrors, BytesAfterTheEndChunk) {
  Bytes b = small_file();
  b.push_back(0);
  expect_error(b, ErrorCode::kCorrupt, "1 bytes follow the end chunk");
}

TEST(ContainerErrors, FileAboveTheSizeLimit) {
  Bytes b = small_file();
  b.resize(kMaxContainerBytes + 1);
  expect_error(b, ErrorCode::kLimit, "above the .cbrdf limit of 67108864 bytes");
}

TEST(ContainerErrors, TooManyChunks) {
  const Bytes b = rebuild(small_file(), [](std::vector<ChunkToWrite>* c) {
    for (std::size_t i = 0; i < kMaxChunks; ++i) c->push_back({"xPAD", {}, false});
  });
  expect_error(b, ErrorCode::kLimit, "above the limit of 1024 chunks per file");
}

TEST(ContainerErrors, TrailingPayloadBytesAreCorruptUnlessTheMinorVersionIsNewer) {
  auto grow = [](Bytes* p) { p->push_back(0); };
  expect_error(edit_payload(small_file(), "HEAD", grow), ErrorCode::kCorrupt,
               "chunk 'HEAD' at offset 12: 1 unexpected bytes after the payload's last field");
  // A file of a newer minor version may append fields this reader does not know. (A minor 2 file
  // has the 1.1 fields: a mixture file, whose MODL ends with them.)
  const Bytes mix = mixture_file();
  const int newer = kContainerMinorVersion + 1;
  EXPECT_TRUE(decode_model(edit_payload(mix, "HEAD", grow, newer)).ok());
  EXPECT_TRUE(decode_model(edit_payload(mix, "MODL", grow, newer)).ok());
  EXPECT_TRUE(decode_model(edit_payload(mix, "MARG", grow, newer)).ok());
  expect_error(edit_payload(mix, "MODL", grow), ErrorCode::kCorrupt,
               "1 unexpected bytes after the payload's last field");
}

TEST(ContainerErrors, UnsupportedGridAndScales) {
  expect_error(edit_payload(small_file(), "HEAD", [](Bytes* p) { (*p)[0] = 45; }),
               ErrorCode::kUnsupported, "grid 45x90x180 is not the MERL grid");
  expect_error(edit_payload(small_file(), "HEAD", [](Bytes* p) { (*p)[6] = 1; }),
               ErrorCode::kUnsupported, "theta_h mapping 1 is unknown");
  expect_error(edit_payload(small_file(), "HEAD",
                            [](Bytes* p) { put_u64(p, 8, std::bit_cast<std::uint64_t>(1.0)); }),
               ErrorCode::kUnsupported, "colour scale factor of R is 1;");
  expect_error(edit_payload(small_file(), "HEAD", [](Bytes* p) { (*p)[32] = 0; }),
               ErrorCode::kCorrupt, "slice count 0 is outside 1..90");
}

// MASK payload: u8 reference, u8 form, u8 values mode, u8 0, u32 count, u64 hash, data, values.
TEST(ContainerErrors, MaskHashMismatch) {
  const Bytes b = edit_payload(small_file(), "MASK", [](Bytes* p) { (*p)[8] ^= 1; });
  expect_error(b, ErrorCode::kChecksum, "the reconstructed mask does not match its hash");
}

TEST(ContainerErrors, MaskCountMismatch) {
  const Bytes b = edit_payload(small_file(), "MASK", [](Bytes* p) { (*p)[4] ^= 1; });
  expect_error(b, ErrorCode::kCorrupt, "not-measured bins but declares");
}

TEST(ContainerErrors, MaskValueNotNegative) {
  const Bytes b = edit_payload(small_file(), "MASK", [](Bytes* p) {
    put_u64(p, p->size() - 8, std::bit_cast<std::uint64_t>(0.0));
  });
  expect_error(b, ErrorCode::kNumeric, "not-measured value 0 at payload offset");
}

TEST(ContainerErrors, MaskModesOutOfRange) {
  const Bytes b = edit_payload(small_file(), "MASK", [](Bytes* p) { (*p)[1] = 2; });
  expect_error(b, ErrorCode::kCorrupt, "form 2");
}

TEST(ContainerErrors, MalformedMetadata) {
  expect_error(edit_payload(small_file(), "mETA",
                            [](Bytes* p) {
                              *p = {'n', 'o', '\n'};
                            }),
               ErrorCode::kCorrupt, "has no '='");
  expect_error(edit_payload(small_file(), "mETA",
                            [](Bytes* p) {
                              *p = {'K', '=', '1', '\n'};
                            }),
               ErrorCode::kCorrupt, "outside [a-z0-9_.]");
  expect_error(edit_payload(small_file(), "mETA",
                            [](Bytes* p) {
                              *p = {'k', '=', '1'};
                            }),
               ErrorCode::kCorrupt, "not terminated by LF");
  expect_error(
      edit_payload(small_file(), "mETA", [](Bytes* p) { *p = {'k', '=', '\n', 'k', '=', '\n'}; }),
      ErrorCode::kCorrupt, "metadata key 'k' at payload offset 3 appears twice");
}

TEST(ContainerErrors, EncoderRefusesBitsOutOfRange) {
  for (int bits : {5, 17}) {
    ContainerSettings s = testing::coding_1_2();
    s.bits = bits;
    Expected<Bytes> b = encode_model(testing::make_model({0, 90}), s);
    ASSERT_FALSE(b.ok());
    EXPECT_EQ(b.status().code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(
        b.status().message().find("bits per code " + std::to_string(bits) + " is outside 6..16"),
        std::string::npos);
  }
}

// ---- Version 1.1: mixtures ------------------------------------------------------------------

TEST(ContainerErrors, MixtureFileIsVersion11AndDecodes) {
  EXPECT_EQ(layout_of(mixture_file()).minor, 1);
  Expected<Model> m = decode_model(mixture_file());
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->slices[0].channel[0].components(), 1);
  EXPECT_EQ(m->slices[0].channel[1].components(), 2);
  EXPECT_EQ(m->slices[0].channel[2].components(), 3);
}

TEST(ContainerErrors, MixtureCountsAndComponentsAreChecked) {
  expect_error(edit_payload(mixture_file(), "MODL", [](Bytes* p) { (*p)[53] = 8; }),
               ErrorCode::kCorrupt,
               "slice 0 channel G has 8 further components; at most 7 are allowed");
  // A count larger than the components present runs off the payload.
  expect_error(edit_payload(mixture_file(), "MODL", [](Bytes* p) { (*p)[53] = 2; }),
               ErrorCode::kTruncated, "copula family needs 1 bytes");
  // Family byte of G's extra component: 9 is no family.
  expect_error(edit_payload(mixture_file(), "MODL", [](Bytes* p) { (*p)[55] = 9; }),
               ErrorCode::kCorrupt, "slice 0 channel G component 1");
  // Its scale: negative.
  expect_error(edit_payload(mixture_file(), "MODL",
                            [](Bytes* p) {
                              const double v = -1.0;
                              std::memcpy(p->data() + 64, &v, 8);
                            }),
               ErrorCode::kNumeric, "slice 0 channel G component 1");
  // A version 1.1 file must hold the counts even when it has no mixture.
  expect_error(rebuild(
                   small_file(), [](std::vector<ChunkToWrite>*) {}, 1),
               ErrorCode::kTruncated, "further component count needs 1 bytes");
}

TEST(ContainerErrors, MarginalLayoutByteMustMatchTheComponents) {
  // In 1.1 the byte says whether component tables follow; it must agree with MODL.
  expect_error(edit_payload(mixture_file(), "MARG", [](Bytes* p) { (*p)[1] = 0; }),
               ErrorCode::kCorrupt,
               "table layout byte at payload offset 1 is 0; it must be 1: MODL declares further "
               "components");
  expect_error(edit_payload(mixture_file(), "MARG", [](Bytes* p) { (*p)[1] = 2; }),
               ErrorCode::kCorrupt, "table layout byte at payload offset 1 is 2");
  // The table count covers every component: 1 + 2 + 3 components x 3 axes = 18.
  expect_error(edit_payload(mixture_file(), "MARG", [](Bytes* p) { (*p)[2] = 17; }),
               ErrorCode::kCorrupt, "table count 17 does not match 6 components x 3 axes");
  // In a 1.0 file the byte is reserved: a 1.0 reader meeting a 1.1 mixture's MARG stops here
  // rather than decoding the first components only.
  expect_error(edit_payload(small_file(), "MARG", [](Bytes* p) { (*p)[1] = 1; }),
               ErrorCode::kCorrupt, "reserved byte at payload offset 1 is not 0");
}

TEST(ContainerErrors, TruncatedMixtureAtEveryChunkBoundaryAndByte) {
  const Bytes& f = mixture_file();
  for (std::size_t n = 0; n < f.size(); ++n) {
    Expected<Model> m = decode_model(Bytes(f.begin(), f.begin() + std::ptrdiff_t(n)));
    ASSERT_FALSE(m.ok()) << n;
  }
}

TEST(ContainerErrors, EncoderRefusesTooManyComponents) {
  Model m = testing::make_mixture_model({0, 90}, 3, 5);
  ChannelSlice& cs = m.slices[0].channel[0];
  while (cs.components() < 9) cs.extra.push_back(m.slices[0].channel[2].extra[0]);
  ContainerSettings s = testing::coding_1_2();
  Expected<Bytes> b = encode_model(m, s);
  ASSERT_FALSE(b.ok());
  EXPECT_EQ(b.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(
      b.status().message().find("slice 0 channel R has 9 components; at most 8 fit in a file"),
      std::string::npos)
      << b.status().message();
}

// The compact framing of version 1.3 (spec 2.2).

const Bytes& small_file13() {
  static const Bytes b = [] {
    ContainerSettings s = testing::coding_1_2();
    s.format = ContainerSettings::Format::kV13;
    s.bits = 8;
    s.zstd_level = 3;
    s.source_name = "errors";
    Expected<Bytes> out = encode_model(testing::make_model({0, 90}, false, 1), s);
    EXPECT_TRUE(out.ok()) << out.status().message();
    return out.ok() ? *out : Bytes{};
  }();
  return b;
}

// A 1.3 file header followed by `body` as it is.
Bytes compact(std::initializer_list<std::uint8_t> body) {
  Bytes b = container_file_header(kContainerMajorVersion, 3);
  b.insert(b.end(), body);
  return b;
}

TEST(ContainerErrorsCompact, ValidFileUsesTheCompactFraming) {
  const ContainerLayout l = layout_of(small_file13());
  ASSERT_EQ(l.minor, 3);
  EXPECT_EQ(chunk(l, "HEAD").offset, 12u);
  EXPECT_EQ(chunk(l, "HEAD").frame_bytes, 5u);  // tag and a 1-byte length field
  EXPECT_EQ(l.chunks.back().frame_bytes, 9u);   // tag, 0, file checksum
  EXPECT_EQ(l.chunks.back().offset + 9, small_file13().size());
}

TEST(ContainerErrorsCompact, TruncatedLengthField) {
  // 'HEAD' and a length byte with its continuation bit set, then the end of the file.
  expect_error(compact({'H', 'E', 'A', 'D', 0x80}), ErrorCode::kTruncated,
               "chunk 'HEAD' at offset 12: length field needs 1 bytes at offset 17 but only 0 "
               "are left");
  // The payload length of a compressed chunk.
  expect_error(compact({'H', 'E', 'A', 'D', 0x09, 0x80}), ErrorCode::kTruncated,
               "chunk 'HEAD' at offset 12: payload length needs 1 bytes at offset 18");
  // Fewer than 5 bytes where a chunk must start.
  expect_error(compact({'H', 'E', 'A'}), ErrorCode::kTruncated,
               "chunk header at offset 12 needs at least 5 bytes but only 3 are left");
}

TEST(ContainerErrorsCompact, OverlongAndOversizedLengthFields) {
  // 8 written as 88 00: a value with two encodings would let two files differ and mean the same.
  expect_error(compact({'H', 'E', 'A', 'D', 0x88, 0x00, 'h', 'd', 0, 0}), ErrorCode::kCorrupt,
               "chunk 'HEAD' at offset 12: length field at offset 16: varint is overlong");
  expect_error(compact({'H', 'E', 'A', 'D', 0x80, 0x80, 0x80, 0x80, 0x80, 0x01}),
               ErrorCode::kCorrupt, "length field at offset 16: varint is longer than 5 bytes");
  expect_error(compact({'H', 'E', 'A', 'D', 0xFF, 0xFF, 0xFF, 0xFF, 0x1F}), ErrorCode::kCorrupt,
               "length field at offset 16: varint exceeds 2^32-1");
  expect_error(compact({'H', 'E', 'A', 'D', 0x09, 0x82, 0x00, 0, 0}), ErrorCode::kCorrupt,
               "chunk 'HEAD' at offset 12: payload length at offset 17: varint is overlong");
}

TEST(ContainerErrorsCompact, LengthPastTheEnd) {
  // Stored length 1000 (field 4000 = A0 1F) with 3 bytes left.
  expect_error(compact({'H', 'E', 'A', 'D', 0xA0, 0x1F, 1, 2, 3}), ErrorCode::kTruncated,
               "chunk 'HEAD' at offset 12: declared length 1000 exceeds the 3 bytes left in the "
               "file");
  // The largest value the field holds: checked before anything is read or allocated.
  expect_error(compact({'M', 'A', 'S', 'K', 0xFC, 0xFF, 0xFF, 0xFF, 0x0F}), ErrorCode::kTruncated,
               "chunk 'MASK' at offset 12: declared length 1073741823 exceeds the 0 bytes left");
  // Every cut of a valid file fails, and never with a checksum error before the framing is read.
  const Bytes& f = small_file13();
  for (std::size_t n = 0; n < f.size(); ++n) {
    Expected<ParsedContainer> pc = parse_container(Bytes(f.begin(), f.begin() + std::ptrdiff_t(n)));
    ASSERT_FALSE(pc.ok()) << n;
    if (n >= 8) {
      EXPECT_EQ(pc.status().code(), ErrorCode::kTruncated) << n << ": " << pc.status().message();
    }
  }
}

TEST(ContainerErrorsCompact, FileChecksum) {
  const Bytes& f = small_file13();
  const ContainerLayout l = layout_of(f);
  const std::size_t sum_at = f.size() - 4;
  // A flipped bit in any payload byte, in a length field's value that still parses, or in the
  // version is caught by the one checksum.
  Bytes b = f;
  b[chunk(l, "BASE").offset + chunk(l, "BASE").frame_bytes + 10] ^= 0x04;
  expect_error(b, ErrorCode::kChecksum,
               "file checksum at offset " + std::to_string(sum_at) + " does not match (stored 0x");
  expect_error(b, ErrorCode::kChecksum,
               "over bytes 0-" + std::to_string(sum_at - 1) + "); the file is damaged");
  b = f;
  b[sum_at + 3] ^= 0x80;  // the checksum itself
  expect_error(b, ErrorCode::kChecksum, "the file is damaged");
  b = f;
  b[10] = 4;  // minor 4 reads the same framing: only the checksum sees it
  expect_error(b, ErrorCode::kChecksum, "the file is damaged");
  // Damage in a zstd frame is reported as damage, before the decompressor sees the frame.
  const Bytes z = [] {
    Bytes out = container_file_header(kContainerMajorVersion, 3);
    Expected<Bytes> frame = zstd_compress(Bytes(500, 7), 3);
    EXPECT_TRUE(frame.ok());
    // The chunk layer does not look inside payloads: an empty BASE stands for the model.
    append_compact_chunk(&out, "HEAD", 0, Bytes(2, 0), 2);
    append_compact_chunk(&out, "BASE", 0, {}, 0);
    append_compact_chunk(&out, "MASK", kChunkFlagZstd, *frame, 500);
    append_compact_end(&out);
    return out;
  }();
  ASSERT_TRUE(parse_container(z).ok()) << parse_container(z).status().message();
  const ChunkInfo mask = chunk(layout_of(z), "MASK");
  ASSERT_TRUE(mask.compressed);
  Bytes zd = z;
  zd[mask.offset + mask.frame_bytes + 3] ^= 0xFF;  // inside the zstd frame
  Expected<ParsedContainer> pc = parse_container(zd);
  ASSERT_FALSE(pc.ok());
  EXPECT_EQ(pc.status().code(), ErrorCode::kChecksum) << pc.status().message();
  // The file ends right after the end chunk: no checksum.
  expect_error(Bytes(f.begin(), f.end() - 4), ErrorCode::kTruncated,
               "the file checksum after the end chunk at offset " +
                   std::to_string(l.chunks.back().offset) + " needs 4 bytes but only 0 are left");
  // Bytes after the checksum.
  b = f;
  b.push_back(0);
  expect_error(b, ErrorCode::kCorrupt, "1 bytes follow the end chunk");
}

TEST(ContainerErrorsCompact, ReservedFlagBitAndEndChunk) {
  // HEAD stored length 2 with flag bit 1: field 2 x 4 + 2 = 10.
  expect_error(compact({'H', 'E', 'A', 'D', 0x0A, 'h', 'd'}), ErrorCode::kCorrupt,
               "chunk 'HEAD' at offset 12: reserved flag bit 1 is set (length field 10; its low "
               "two bits are the flags, only bit 0 is defined)");
  expect_error(compact({'H', 'E', 'A', 'D', 0x0B, 0x02, 'h', 'd'}), ErrorCode::kCorrupt,
               "reserved flag bit 1 is set (length field 11");
  // The end chunk holds nothing and sets no flag.
  expect_error(
      compact({'H', 'E', 'A', 'D', 0x08, 'h', 'd', 'C', 'E', 'N', 'D', 0x04, 0, 1, 2, 3, 4}),
      ErrorCode::kCorrupt,
      "chunk 'CEND' at offset 19: the end chunk must be empty and unflagged (length "
      "field 4, expected 0)");
  // A valid frame sequence whose chunks break the rules after the checksum: HEAD not first.
  Bytes b = container_file_header(kContainerMajorVersion, 3);
  append_compact_chunk(&b, "MASK", 0, Bytes(2, 0), 2);
  append_compact_end(&b);
  expect_error(b, ErrorCode::kCorrupt, "chunk 'MASK' at offset 12: the first chunk must be 'HEAD'");
}

TEST(ContainerErrorsCompact, LimitsAfterTheChecksumBeforeAllocation) {
  // A compressed HEAD declaring a 257-byte payload (its limit is 256): refused from the field,
  // before the frame is decompressed.
  Expected<Bytes> frame = zstd_compress(Bytes(257, 0), 3);
  ASSERT_TRUE(frame.ok());
  Bytes b = container_file_header(kContainerMajorVersion, 3);
  append_compact_chunk(&b, "HEAD", kChunkFlagZstd, *frame, 257);
  append_compact_end(&b);
  expect_error(b, ErrorCode::kLimit,
               "chunk 'HEAD' at offset 12: payload of 257 bytes exceeds the limit of 256 bytes");
  // A declared payload length of 2^32-1 for MASK: the same, from the field alone.
  b = container_file_header(kContainerMajorVersion, 3);
  append_compact_chunk(&b, "HEAD", 0, Bytes(2, 0), 2);
  append_compact_chunk(&b, "MASK", kChunkFlagZstd, *frame, 0xFFFFFFFFu);
  append_compact_end(&b);
  expect_error(b, ErrorCode::kLimit, "chunk 'MASK' at offset 19: payload of 4294967295 bytes");
}

TEST(ContainerErrorsCompact, TooManyChunks) {
  const Bytes b = rebuild(small_file13(), [](std::vector<ChunkToWrite>* c) {
    for (std::size_t i = 0; i < kMaxChunks; ++i) c->push_back({"xPAD", {}, false});
  });
  ASSERT_TRUE(uses_compact_framing(layout_of(small_file13()).minor));
  // 1024 chunks, the end chunk included, are allowed; the 1025th is not.
  const ContainerLayout ok = layout_of(rebuild(small_file13(), [](std::vector<ChunkToWrite>* c) {
    while (c->size() + 1 < kMaxChunks) c->push_back({"xPAD", {}, false});
  }));
  EXPECT_EQ(ok.chunks.size(), kMaxChunks);
  expect_error(b, ErrorCode::kLimit, "would be chunk number 1025, above the limit of 1024 chunks");
}

TEST(ContainerErrorsCompact, NewerMinorVersionReadsTheSameFraming) {
  auto grow = [](Bytes* p) { p->push_back(0); };
  const Bytes newer = edit_payload(small_file13(), "HEAD", grow, kContainerMinorVersion + 1);
  Expected<Model> m = decode_model(newer);
  ASSERT_TRUE(m.ok()) << m.status().message();
  Expected<Model> ref = decode_model(small_file13());
  ASSERT_TRUE(ref.ok());
  EXPECT_EQ(m->slices[0].channel[1].pdf_d, ref->slices[0].channel[1].pdf_d);
  expect_error(edit_payload(small_file13(), "HEAD", grow), ErrorCode::kCorrupt,
               "chunk 'HEAD' at offset 12: 1 unexpected bytes after the payload's last field");
}

}  // namespace
}  // namespace cbrdf
