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
  Expected<std::vector<std::uint8_t>> file = write_container(minimal_chunks(), 3);
  ASSERT_TRUE(file.ok());
  (*file)[10] = 7;  // minor 7: backward-compatible additions only
  Expected<ParsedContainer> pc = parse_container(*file);
  ASSERT_TRUE(pc.ok()) << pc.status().message();
  EXPECT_EQ(pc->layout.minor, 7);
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

TEST(Quantize, CodesSpanTheRangeAndDecodeWithinTheBound) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> logm(-30.0, 0.0);
  std::vector<double> t(500);
  for (double& v : t) v = std::exp(logm(rng));
  t[17] = 0.0;
  for (int bits = kMinMarginalBits; bits <= kMaxMarginalBits; ++bits) {
    const QuantizedTable q = quantize_masses(t, bits);
    EXPECT_EQ(q.codes[17], 0u);
    EXPECT_EQ(*std::max_element(q.codes.begin(), q.codes.end()), max_code(bits));
    EXPECT_EQ(*std::min_element(q.codes.begin(), q.codes.end()), 0u);
    Expected<std::vector<double>> d = dequantize_masses(q, bits);
    ASSERT_TRUE(d.ok());
    double sum = 0;
    for (double v : t) sum += v;
    double worst = 0;
    for (std::size_t i = 0; i < t.size(); ++i) {
      if (t[i] > 0) worst = std::max(worst, std::abs((*d)[i] / (t[i] / sum) - 1));
    }
    const double bound = relative_error_bound(q, bits);
    EXPECT_LE(worst, bound * (1 + 1e-9));
    EXPECT_GT(worst, 0.3 * bound);  // the bound is tight, not decorative
  }
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
