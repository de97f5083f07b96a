// SPDX-License-Identifier: MIT
// The chunk layer on its own: writing and parsing, compression choice, tag rules, unknown chunks,
// the byte reader every parser uses, and the worked example of spec/container.md.
#include "cbrdf/container.h"

#include <gtest/gtest.h>

#include <random>
#include <string>

#include "bitstream/quantize.h"
#include "byte_reader.h"
#include "byte_writer.h"
#include "test_support.h"
#include "zstd_util.h"

namespace cbrdf {
namespace {
using testing::bytes_of;

// The critical chunks a valid file needs; the chunk layer does not look inside payloads.
std::vector<ChunkToWrite> minimal_chunks() {
  return {{"HEAD", bytes_of("head"), false},
          {"MODL", std::vector<std::uint8_t>(4000, 7), true},  // compressible
          {"MARG", bytes_of("marg"), true},                    // too small to gain
          {"MASK", bytes_of("mask"), false}};
}

TEST(Container, SpecWorkedExampleBytes) {
  // spec/container.md, "Worked example": ancillary chunk 'zTST' holding "hi".
  std::vector<std::uint8_t> out;
  append_raw_chunk(&out, "zTST", 0, bytes_of("hi"), 2);
  const std::vector<std::uint8_t> expected = {0x7A, 0x54, 0x53, 0x54, 0x02, 0x00, 0x00, 0x00, 0x00,
                                              0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0x68, 0x69,
                                              0xCA, 0x4D, 0xF5, 0xB2, 0x21, 0x9A, 0x92, 0x63};
  EXPECT_EQ(out, expected);
  EXPECT_EQ(chunk_checksum(std::span(out).first(18)), 0x63929A21B2F54DCAull);
  EXPECT_EQ(container_file_header(),
            (std::vector<std::uint8_t>{0x8B, 0x43, 0x42, 0x52, 0x0D, 0x0A, 0x1A, 0x0A, 0x01, 0x00,
                                       0x00, 0x00}));
}

TEST(Container, WriteThenParseKeepsPayloadsOrderAndOffsets) {
  const std::vector<ChunkToWrite> chunks = minimal_chunks();
  Expected<std::vector<std::uint8_t>> file = write_container(chunks, 19);
  ASSERT_TRUE(file.ok()) << file.status().message();
  Expected<ParsedContainer> pc = parse_container(*file);
  ASSERT_TRUE(pc.ok()) << pc.status().message();
  EXPECT_EQ(pc->layout.major, 1);
  EXPECT_EQ(pc->layout.minor, 0);
  EXPECT_EQ(pc->layout.file_bytes, file->size());
  ASSERT_EQ(pc->layout.chunks.size(), chunks.size() + 1);
  std::uint64_t offset = kContainerHeaderBytes;
  for (std::size_t i = 0; i < chunks.size(); ++i) {
    const ChunkInfo& c = pc->layout.chunks[i];
    EXPECT_EQ(c.tag, chunks[i].tag);
    EXPECT_EQ(c.offset, offset);
    EXPECT_TRUE(c.known);
    EXPECT_TRUE(c.critical);
    EXPECT_EQ(c.payload_bytes, chunks[i].payload.size());
    EXPECT_EQ(pc->payloads[i], chunks[i].payload);
    offset += kChunkHeaderBytes + c.stored_bytes + kChunkChecksumBytes;
  }
  EXPECT_EQ(pc->layout.chunks.back().tag, "CEND");
  EXPECT_EQ(offset + kChunkHeaderBytes + kChunkChecksumBytes, file->size());
  // zstd is kept only where it pays.
  EXPECT_TRUE(pc->layout.chunks[1].compressed);
  EXPECT_LT(pc->layout.chunks[1].stored_bytes, 100u);
  EXPECT_FALSE(pc->layout.chunks[2].compressed);
  EXPECT_FALSE(pc->layout.chunks[0].compressed);
  EXPECT_EQ(pc->find("MASK"), 3);
  EXPECT_EQ(pc->find("mETA"), -1);
}

TEST(Container, UnknownAncillaryChunksAreSkippedAndListed) {
  std::vector<ChunkToWrite> chunks = minimal_chunks();
  chunks.insert(chunks.begin() + 2, {"xFUT", std::vector<std::uint8_t>(3000, 1), true});
  Expected<std::vector<std::uint8_t>> file = write_container(chunks, 3);
  ASSERT_TRUE(file.ok());
  Expected<ParsedContainer> pc = parse_container(*file);
  ASSERT_TRUE(pc.ok()) << pc.status().message();
  const ChunkInfo& c = pc->layout.chunks[2];
  EXPECT_EQ(c.tag, "xFUT");
  EXPECT_FALSE(c.known);
  EXPECT_FALSE(c.critical);
  EXPECT_TRUE(c.compressed);
  EXPECT_EQ(c.payload_bytes, 3000u);
  EXPECT_TRUE(pc->payloads[2].empty());  // never decompressed
  EXPECT_EQ(pc->payloads[3], bytes_of("marg"));
}

TEST(Container, NewerMinorVersionIsAccepted) {
  // Minor versions from 3 on use the compact framing, whose file checksum covers the version.
  Expected<std::vector<std::uint8_t>> file = write_container(minimal_chunks(), 3, 3);
  ASSERT_TRUE(file.ok());
  (*file)[10] = 7;  // minor 7: backward-compatible additions only
  file->resize(file->size() - kFileChecksumBytes);
  const std::uint32_t sum = file_checksum(*file);
  for (int i = 0; i < 4; ++i) file->push_back(std::uint8_t(sum >> (8 * i)));
  Expected<ParsedContainer> pc = parse_container(*file);
  ASSERT_TRUE(pc.ok()) << pc.status().message();
  EXPECT_EQ(pc->layout.minor, 7);
  EXPECT_EQ(pc->payloads[1], minimal_chunks()[1].payload);
}

TEST(Container, VersionIsReadFromTheHeaderAloneWithTheParsersChecks) {
  for (std::uint16_t minor : {0, 2, 3}) {
    Expected<std::vector<std::uint8_t>> file = write_container(minimal_chunks(), 3, minor);
    ASSERT_TRUE(file.ok());
    Expected<ContainerLayout> v = read_container_version(*file);
    ASSERT_TRUE(v.ok()) << v.status().message();
    EXPECT_EQ(v->major, kContainerMajorVersion);
    EXPECT_EQ(v->minor, minor);
    EXPECT_EQ(v->file_bytes, file->size());
    EXPECT_TRUE(v->chunks.empty());
    // The header alone is enough: the chunks are not read.
    file->resize(kContainerHeaderBytes);
    v = read_container_version(*file);
    ASSERT_TRUE(v.ok()) << v.status().message();
    EXPECT_EQ(v->minor, minor);
  }
  const std::vector<std::uint8_t> header = container_file_header(1, 3);
  Expected<ContainerLayout> v =
      read_container_version(std::span(header).first(kContainerHeaderBytes - 1));
  EXPECT_EQ(v.status().code(), ErrorCode::kTruncated);
  EXPECT_NE(v.status().message().find("minor version"), std::string::npos) << v.status().message();
  std::vector<std::uint8_t> lf = header;
  lf.erase(lf.begin() + 4);  // CR LF -> LF, as a text-mode transfer does
  v = read_container_version(lf);
  EXPECT_EQ(v.status().code(), ErrorCode::kBadSignature);
  EXPECT_NE(v.status().message().find("CR LF was converted"), std::string::npos);
  v = read_container_version(container_file_header(2, 0));
  EXPECT_EQ(v.status().code(), ErrorCode::kUnsupported);
  EXPECT_NE(v.status().message().find("use a newer cbrdf"), std::string::npos);
  v = read_container_version(container_file_header(0, 3));
  EXPECT_EQ(v.status().code(), ErrorCode::kCorrupt);
}

TEST(Container, SpecWorkedExampleCompactFraming) {
  // spec/container.md 2.2, "Worked example": a 1.3 file of 'HEAD' holding "hd" and the end chunk.
  std::vector<std::uint8_t> out = container_file_header(1, 3);
  append_compact_chunk(&out, "HEAD", 0, bytes_of("hd"), 2);
  append_compact_end(&out);
  const std::vector<std::uint8_t> expected = {
      0x8B, 0x43, 0x42, 0x52, 0x0D, 0x0A, 0x1A, 0x0A, 0x01, 0x00, 0x03, 0x00,  // header
      0x48, 0x45, 0x41, 0x44, 0x08, 0x68, 0x64,  // 'HEAD', 2 x 4 + 0, "hd"
      0x43, 0x45, 0x4E, 0x44, 0x00,              // 'CEND', 0
      0x6C, 0x31, 0x1E, 0x75};                   // low 32 bits of XXH64 of the 24 bytes before
  EXPECT_EQ(out, expected);
  EXPECT_EQ(file_checksum(std::span(out).first(24)), 0x751E316Cu);
  // A compressed chunk: length field 300 x 4 + 1 = 1201 (B1 09), then payload length 70000
  // (F0 A2 04).
  std::vector<std::uint8_t> z;
  append_compact_chunk(&z, "MARG", kChunkFlagZstd, std::vector<std::uint8_t>(300, 0), 70000);
  EXPECT_EQ(std::vector<std::uint8_t>(z.begin() + 4, z.begin() + 9),
            (std::vector<std::uint8_t>{0xB1, 0x09, 0xF0, 0xA2, 0x04}));
  EXPECT_EQ(z.size(), 9u + 300u);
}

TEST(Container, CompactFramingRoundTripsWithOffsetsAndFrameSizes) {
  std::vector<ChunkToWrite> chunks = minimal_chunks();
  chunks.insert(chunks.begin() + 2, {"xFUT", std::vector<std::uint8_t>(3000, 1), true});
  Expected<std::vector<std::uint8_t>> file = write_container(chunks, 19, 3);
  ASSERT_TRUE(file.ok()) << file.status().message();
  Expected<ParsedContainer> pc = parse_container(*file);
  ASSERT_TRUE(pc.ok()) << pc.status().message();
  EXPECT_EQ(pc->layout.minor, 3);
  ASSERT_EQ(pc->layout.chunks.size(), chunks.size() + 1);
  std::uint64_t offset = kContainerHeaderBytes;
  std::uint64_t framing = kContainerHeaderBytes;
  for (std::size_t i = 0; i < pc->layout.chunks.size(); ++i) {
    const ChunkInfo& c = pc->layout.chunks[i];
    EXPECT_EQ(c.offset, offset) << c.tag;
    if (i < chunks.size()) {
      EXPECT_EQ(c.tag, chunks[i].tag);
      EXPECT_EQ(c.payload_bytes, chunks[i].payload.size());
      if (c.known) {
        EXPECT_EQ(pc->payloads[i], chunks[i].payload);
      }
    }
    offset += c.frame_bytes + c.stored_bytes;
    framing += c.frame_bytes;
  }
  EXPECT_EQ(offset, file->size());
  // HEAD 4+1, MODL (zstd, 4000 -> under 32 bytes) 4+1+2, xFUT (zstd) 4+1+2, MARG 4+1, MASK 4+1,
  // CEND 4+1+4.
  EXPECT_EQ(pc->layout.chunks[1].frame_bytes, 7u);
  EXPECT_EQ(pc->layout.chunks[2].frame_bytes, 7u);
  EXPECT_EQ(pc->layout.chunks[3].frame_bytes, 5u);
  EXPECT_EQ(pc->layout.chunks.back().frame_bytes, 9u);
  EXPECT_EQ(framing, 12u + 5 + 7 + 7 + 5 + 5 + 9);
  EXPECT_TRUE(pc->layout.chunks[1].compressed);
  EXPECT_FALSE(pc->layout.chunks[2].known);
  EXPECT_TRUE(pc->payloads[2].empty());  // unknown: never decompressed
  EXPECT_EQ(pc->layout.chunks.back().checksum,
            file_checksum(std::span(*file).first(file->size() - 4)));
  // The same chunks in the 1.0 framing: 24 bytes per chunk.
  Expected<std::vector<std::uint8_t>> old = write_container(chunks, 19, 0);
  ASSERT_TRUE(old.ok());
  Expected<ParsedContainer> pc0 = parse_container(*old);
  ASSERT_TRUE(pc0.ok());
  for (const ChunkInfo& c : pc0->layout.chunks) EXPECT_EQ(c.frame_bytes, 24u) << c.tag;
  EXPECT_EQ(old->size() - file->size(), 12 + 6 * 24 - framing);
}

std::size_t varint_size(std::size_t v) {
  std::size_t n = 1;
  for (; v >= 0x80; v >>= 7) ++n;
  return n;
}

TEST(Container, CompactFramingKeepsZstdOnlyWhereItPaysWithItsLengthField) {
  // Random bytes after a run of zeros: as the run grows, zstd goes from losing to winning by a
  // byte or two, where the compact framing's payload length field decides.
  std::mt19937 rng(5);
  int compressed_only_in_old_framing = 0;
  for (std::size_t zeros = 0; zeros < 48; ++zeros) {
    std::vector<std::uint8_t> p(150, 0);
    for (std::size_t k = zeros; k < p.size(); ++k) p[k] = std::uint8_t(rng());
    std::vector<ChunkToWrite> chunks = minimal_chunks();
    chunks.push_back({"xRND", p, true});
    Expected<std::vector<std::uint8_t>> z = zstd_compress(p, 19);
    ASSERT_TRUE(z.ok());
    const std::size_t as_raw = 4 + varint_size(p.size() * 4) + p.size();
    const std::size_t as_zstd =
        4 + varint_size(z->size() * 4 + 1) + varint_size(p.size()) + z->size();
    Expected<std::vector<std::uint8_t>> file = write_container(chunks, 19, 3);
    ASSERT_TRUE(file.ok());
    Expected<ParsedContainer> pc = parse_container(*file);
    ASSERT_TRUE(pc.ok()) << pc.status().message();
    const ChunkInfo& c = pc->layout.chunks[4];
    EXPECT_EQ(c.frame_bytes + c.stored_bytes, std::min(as_raw, as_zstd)) << zeros;
    EXPECT_EQ(c.compressed, as_zstd < as_raw) << zeros;
    if (z->size() < p.size() && as_zstd >= as_raw) ++compressed_only_in_old_framing;
  }
  EXPECT_GT(compressed_only_in_old_framing, 0);  // the sweep reaches the case that matters
}

TEST(Container, TagRules) {
  EXPECT_TRUE(chunk_tag_valid("HEAD"));
  EXPECT_TRUE(chunk_tag_valid("mETA"));
  EXPECT_TRUE(chunk_tag_valid("xF2T"));
  EXPECT_FALSE(chunk_tag_valid("HEA"));
  EXPECT_FALSE(chunk_tag_valid("1ABC"));
  EXPECT_FALSE(chunk_tag_valid("Abcd"));  // only the first letter's case carries meaning
  EXPECT_FALSE(chunk_tag_valid("AB C"));
  EXPECT_TRUE(chunk_tag_critical("MARG"));
  EXPECT_FALSE(chunk_tag_critical("mETA"));
  EXPECT_TRUE(chunk_tag_known("CEND"));
  EXPECT_TRUE(chunk_tag_known("mETA"));
  EXPECT_FALSE(chunk_tag_known("XTRA"));
  EXPECT_EQ(max_chunk_payload_bytes("XTRA"), 0u);
  EXPECT_GT(max_chunk_payload_bytes("MASK"), 35'000'000u);  // one value per bin must fit
}

TEST(Container, WriterRefusesBadTagsAndOversizedPayloads) {
  std::vector<ChunkToWrite> chunks = minimal_chunks();
  chunks.push_back({"CEND", {}, false});
  Expected<std::vector<std::uint8_t>> a = write_container(chunks, 3);
  ASSERT_FALSE(a.ok());
  EXPECT_EQ(a.status().code(), ErrorCode::kInvalidArgument);
  chunks = minimal_chunks();
  chunks[0].payload.assign(max_chunk_payload_bytes("HEAD") + 1, 0);
  Expected<std::vector<std::uint8_t>> b = write_container(chunks, 3);
  ASSERT_FALSE(b.ok());
  EXPECT_EQ(b.status().code(), ErrorCode::kLimit);
  EXPECT_NE(b.status().message().find("'HEAD'"), std::string::npos);
}

TEST(ByteReader, ReadsLittleEndianAndReportsTruncationWithOffsets) {
  const std::vector<std::uint8_t> data = {0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07};
  ByteReader r(data, 100);
  std::uint16_t a = 0;
  std::uint32_t b = 0;
  ASSERT_TRUE(r.u16(&a, "a").ok());
  EXPECT_EQ(a, 0x0201);
  ASSERT_TRUE(r.u32(&b, "b").ok());
  EXPECT_EQ(b, 0x06050403u);
  EXPECT_EQ(r.offset(), 106u);
  std::uint32_t c = 0;
  const Status st = r.u32(&c, "field c");
  EXPECT_EQ(st.code(), ErrorCode::kTruncated);
  EXPECT_EQ(st.message(), "field c needs 4 bytes at offset 106 but only 1 are left");
  EXPECT_EQ(r.remaining(), 1u);  // a failed read consumes nothing
}

TEST(ByteReader, VarintsRoundTripAndRejectOverlongForms) {
  ByteWriter w;
  const std::vector<std::uint32_t> values = {0, 1, 127, 128, 300, 16383, 16384, 0xFFFFFFFFu};
  for (std::uint32_t v : values) w.varint32(v);
  ByteReader r(w.data());
  for (std::uint32_t v : values) {
    std::uint32_t got = 0;
    ASSERT_TRUE(r.varint32(&got, "v").ok());
    EXPECT_EQ(got, v);
  }
  EXPECT_TRUE(r.at_end());
  auto bad = [](std::vector<std::uint8_t> bytes, ErrorCode code, const std::string& needle) {
    ByteReader br(bytes);
    std::uint32_t v = 0;
    const Status st = br.varint32(&v, "v");
    EXPECT_EQ(st.code(), code);
    EXPECT_NE(st.message().find(needle), std::string::npos) << st.message();
  };
  bad({0x80, 0x00}, ErrorCode::kCorrupt, "overlong");
  bad({0xFF, 0xFF, 0xFF, 0xFF, 0x1F}, ErrorCode::kCorrupt, "exceeds");
  bad({0x80, 0x80, 0x80, 0x80, 0x80, 0x01}, ErrorCode::kCorrupt, "longer than 5");
  bad({0x80, 0x80}, ErrorCode::kTruncated, "needs 1 bytes");
}

TEST(Quantize, ZigzagIsABijectionOnSmallValues) {
  for (std::int32_t v = -70000; v <= 70000; ++v) {
    ASSERT_EQ(unzigzag(zigzag(v)), v);
  }
  EXPECT_EQ(zigzag(0), 0u);
  EXPECT_EQ(zigzag(-1), 1u);
  EXPECT_EQ(zigzag(1), 2u);
}

TEST(Quantize, DecoderRefusesBadRangesAndCodes) {
  QuantizedTable q;
  q.codes = {0, 5, 63};
  q.lo = -10.0f;
  q.hi = 0.0f;
  EXPECT_TRUE(dequantize_masses(q, 6).ok());
  q.codes[1] = 64;
  EXPECT_EQ(dequantize_masses(q, 6).status().code(), ErrorCode::kCorrupt);
  q.codes[1] = 5;
  q.lo = 1.0f;
  EXPECT_EQ(dequantize_masses(q, 6).status().code(), ErrorCode::kNumeric);
  q.lo = -1000.0f;
  EXPECT_EQ(dequantize_masses(q, 6).status().code(), ErrorCode::kNumeric);
  q.lo = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(dequantize_masses(q, 6).status().code(), ErrorCode::kNumeric);
}

}  // namespace
}  // namespace cbrdf
