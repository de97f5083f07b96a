// SPDX-License-Identifier: MIT
// The resource bounds of spec/container.md ("Resource bounds"): a hostile file is refused before
// anything of its declared size is allocated, a decompression bomb is refused, and the largest
// legitimate file decodes within the documented heap bound. Heap use is measured with a replaced
// global operator new (this test binary only), as tests/format/merl_io_test.cc does.
#include <gtest/gtest.h>
#include <malloc.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <new>
#include <vector>

#include "cbrdf/codec.h"
#include "cbrdf/container.h"
#include "cbrdf/container_writer.h"
#include "coding_1_2.h"
#include "heap_meter.h"
#include "synthetic_model.h"
#include "zstd_util.h"

namespace cbrdf {
namespace {

using Bytes = std::vector<std::uint8_t>;
constexpr std::size_t kMiB = std::size_t{1} << 20;

// spec/container.md, "Resource bounds": its decode peak (192 MiB) is reached with a residual
// layer; these files hold none, so their stage stays under the MASK stage's 115 MiB and, as
// computed for the largest Model without RESD (payloads, mask and values, slices), under 80 MiB.
constexpr std::size_t kDecodeHeapBound = 80 * kMiB;  // decode_model / inspect_container
constexpr std::size_t kTableHeapBound = 40 * kMiB;   // table() on top of the Model

using Meter = testing::heap::Meter;

// A valid HEAD, then the chunk under test, then the file's other chunks and its end: the parser
// reaches the chunk under test with the file otherwise sound (it checks the whole set of chunks
// before it decompresses any).
Bytes head_then(std::string_view tag, std::uint32_t flags, const Bytes& stored,
                std::uint32_t payload_bytes) {
  Expected<Bytes> base = encode_model(testing::make_model({0, 90}), testing::coding_1_2());
  EXPECT_TRUE(base.ok());
  Expected<ParsedContainer> pc = parse_container(*base);
  EXPECT_TRUE(pc.ok());
  EXPECT_FALSE(uses_compact_framing(pc->layout.minor));
  Bytes file = container_file_header(kContainerMajorVersion, pc->layout.minor);
  const Bytes& head = pc->payloads[std::size_t(pc->find(kTagHeader))];
  append_raw_chunk(&file, kTagHeader, 0, head, std::uint32_t(head.size()));
  append_raw_chunk(&file, tag, flags, stored, payload_bytes);
  for (std::size_t i = 0; i < pc->layout.chunks.size(); ++i) {
    const std::string& t = pc->layout.chunks[i].tag;
    if (t == kTagHeader || t == tag || t == kTagEnd) continue;
    append_raw_chunk(&file, t, 0, pc->payloads[i], std::uint32_t(pc->payloads[i].size()));
  }
  append_raw_chunk(&file, kTagEnd, 0, {}, 0);
  return file;
}

TEST(ResourceBounds, FileAboveTheContainerLimitIsRefusedWithoutAllocating) {
  Bytes file(kMaxContainerBytes + 1, 0);
  std::copy(kContainerSignature.begin(), kContainerSignature.end(), file.begin());
  Meter m;
  m.start();
  Expected<Model> model = decode_model(file);
  ASSERT_FALSE(model.ok());
  EXPECT_EQ(model.status().code(), ErrorCode::kLimit) << model.status().message();
  EXPECT_LT(m.largest_bytes(), 64 * 1024u) << "refused before reading the file's contents";
}

TEST(ResourceBounds, DeclaredLengthBeyondTheFileIsRefusedBeforeAllocation) {
  // The chunk claims 4 GB; the file holds a few bytes.
  Bytes file = container_file_header();
  append_raw_chunk(&file, kTagHeader, 0, Bytes(34, 0), 34);
  const std::uint32_t huge = 0xFFFFFFF0u;
  for (int i = 0; i < 4; ++i) file[12 + 4 + std::size_t(i)] = std::uint8_t(huge >> (8 * i));
  Meter m;
  m.start();
  Expected<ParsedContainer> pc = parse_container(file);
  ASSERT_FALSE(pc.ok());
  EXPECT_EQ(pc.status().code(), ErrorCode::kTruncated) << pc.status().message();
  EXPECT_NE(pc.status().message().find("4294967280"), std::string::npos) << pc.status().message();
  EXPECT_LT(m.largest_bytes(), 64 * 1024u);
}

TEST(ResourceBounds, PayloadAboveItsChunkLimitIsRefusedBeforeDecompression) {
  // A MASK that declares one byte more than its 36 MiB maximum, stored as a tiny zstd frame.
  const std::uint32_t limit = max_chunk_payload_bytes(kTagMask);
  ASSERT_EQ(limit, 36u * kMiB);
  Expected<Bytes> frame = zstd_compress(Bytes(1000, 0), 3);
  ASSERT_TRUE(frame.ok());
  const Bytes file = head_then(kTagMask, kChunkFlagZstd, *frame, limit + 1);
  Meter m;
  m.start();
  Expected<Model> model = decode_model(file);
  ASSERT_FALSE(model.ok());
  EXPECT_EQ(model.status().code(), ErrorCode::kLimit) << model.status().message();
  EXPECT_NE(model.status().message().find("chunk 'MASK'"), std::string::npos);
  EXPECT_LT(m.largest_bytes(), 64 * 1024u) << "nothing of the declared size was allocated";
}

TEST(ResourceBounds, UncompressedPayloadAboveItsLimitIsNotCopied) {
  // 2 MiB + 1 bytes really stored in a MARG chunk (limit 2 MiB): refused, the bytes never copied.
  const std::uint32_t n = max_chunk_payload_bytes(kTagMarginals) + 1;
  const Bytes file = head_then(kTagMarginals, 0, Bytes(n, 0x55), n);
  Meter m;
  m.start();
  Expected<ParsedContainer> pc = parse_container(file);
  ASSERT_FALSE(pc.ok());
  EXPECT_EQ(pc.status().code(), ErrorCode::kLimit) << pc.status().message();
  EXPECT_LT(m.largest_bytes(), 64 * 1024u);
}

// Offset of the Frame_Content_Size field of a zstd frame (RFC 8878, 3.1.1.1) and its size.
std::pair<std::size_t, std::size_t> content_size_field(const Bytes& frame) {
  const std::uint8_t fhd = frame[4];
  const int fcs_flag = fhd >> 6;
  const bool single_segment = (fhd >> 5) & 1;
  const int dict_flag = fhd & 3;
  const std::size_t dict_bytes = dict_flag == 0 ? 0 : dict_flag == 1 ? 1 : dict_flag == 2 ? 2 : 4;
  const std::size_t at = 5 + (single_segment ? 0 : 1) + dict_bytes;
  const std::size_t size = fcs_flag == 0 ? (single_segment ? 1 : 0) : std::size_t{1} << fcs_flag;
  return {at, size};
}

TEST(ResourceBounds, DecompressionBombIsRefused) {
  // 16 MiB of zeros compress to a few hundred bytes; the frame's header is changed to declare
  // 1,000 bytes of content, matching the chunk's P. The decoder decompresses into a buffer of
  // exactly P bytes, so the bomb fails instead of expanding.
  Expected<Bytes> frame = zstd_compress(Bytes(16 * kMiB, 0), 3);
  ASSERT_TRUE(frame.ok());
  ASSERT_LT(frame->size(), 4096u);
  const auto [at, size] = content_size_field(*frame);
  ASSERT_EQ(size, 4u) << "a 16 MiB frame stores its content size in 4 bytes";
  const std::uint32_t declared = 1000;
  for (std::size_t i = 0; i < 4; ++i) (*frame)[at + i] = std::uint8_t(declared >> (8 * i));

  const Bytes file = head_then(kTagMarginals, kChunkFlagZstd, *frame, declared);
  Meter m;
  m.start();
  Expected<Model> model = decode_model(file);
  ASSERT_FALSE(model.ok());
  EXPECT_EQ(model.status().code(), ErrorCode::kCorrupt) << model.status().message();
  EXPECT_NE(model.status().message().find("chunk 'MARG'"), std::string::npos);
  EXPECT_LT(m.peak_bytes(), 1 * kMiB) << "the bomb did not expand";
}

TEST(ResourceBounds, FrameDeclaringMoreThanTheChunkIsRefusedBeforeAllocation) {
  Expected<Bytes> frame = zstd_compress(Bytes(16 * kMiB, 0), 3);
  ASSERT_TRUE(frame.ok());
  const Bytes file = head_then(kTagMarginals, kChunkFlagZstd, *frame, 1000);
  Meter m;
  m.start();
  Expected<Model> model = decode_model(file);
  ASSERT_FALSE(model.ok());
  EXPECT_EQ(model.status().code(), ErrorCode::kCorrupt) << model.status().message();
  EXPECT_NE(model.status().message().find("16777216"), std::string::npos)
      << model.status().message();
  EXPECT_LT(m.largest_bytes(), 64 * 1024u);
}

TEST(ResourceBounds, MaximalMaskBombStaysWithinTheDecodeBound) {
  // A MASK chunk of the largest payload allowed, 36 MiB of zeros in a small frame: the decoder may
  // allocate that much (it is the documented maximum), and must then refuse the content.
  Expected<Bytes> frame = zstd_compress(Bytes(max_chunk_payload_bytes(kTagMask), 0), 3);
  ASSERT_TRUE(frame.ok());
  ASSERT_LT(frame->size(), 64 * 1024u);
  Expected<Bytes> good = encode_model(testing::make_model({0, 90}), testing::coding_1_2());
  ASSERT_TRUE(good.ok());
  Expected<ParsedContainer> pc = parse_container(*good);
  ASSERT_TRUE(pc.ok());
  std::vector<ChunkToWrite> chunks;
  for (std::size_t i = 0; i + 1 < pc->layout.chunks.size(); ++i) {
    if (pc->layout.chunks[i].tag != kTagMask) {
      chunks.push_back({pc->layout.chunks[i].tag, pc->payloads[i], false});
    }
  }
  Expected<Bytes> without_mask = write_container(chunks, 1);
  ASSERT_TRUE(without_mask.ok());
  Bytes file(without_mask->begin(), without_mask->end() - 24);  // before CEND
  append_raw_chunk(&file, kTagMask, kChunkFlagZstd, *frame, max_chunk_payload_bytes(kTagMask));
  append_raw_chunk(&file, kTagEnd, 0, {}, 0);

  Meter m;
  m.start();
  Expected<Model> model = decode_model(file);
  ASSERT_FALSE(model.ok());
  // An all-clear bitmap with count 0 passes the count check and fails the mask hash.
  EXPECT_EQ(model.status().code(), ErrorCode::kChecksum) << model.status().message();
  EXPECT_LE(m.peak_bytes(), kDecodeHeapBound);
  EXPECT_GE(m.peak_bytes(), std::size_t{36} * kMiB) << "the meter saw the payload";
}

TEST(ResourceBounds, LargestLegitimateFileDecodesWithinTheDocumentedBounds) {
  // Every bin not measured, one distinct stored value per bin: the largest Model a file can hold.
  Model model = testing::make_model(testing::six_slices());
  model.not_measured = NotMeasured{};
  model.not_measured.bits.assign(model.not_measured.bits.size(), ~std::uint64_t{0});
  const std::size_t bins = std::size_t{kChannels} * kBinsPerChannel;
  model.not_measured.bits.back() >>= 64 - bins % 64;
  model.not_measured.values.resize(bins);
  for (std::size_t i = 0; i < bins; ++i) model.not_measured.values[i] = -1.0 - double(i % 1000);
  ContainerSettings settings = testing::coding_1_2();
  settings.zstd_level = 1;
  Expected<Bytes> file = encode_model(model, settings);
  ASSERT_TRUE(file.ok()) << file.status().message();
  ASSERT_LE(file->size(), kMaxContainerBytes);
  model = Model{};  // only the file stays alive

  Meter m;
  m.start();
  Expected<Model> decoded = decode_model(*file);
  ASSERT_TRUE(decoded.ok()) << decoded.status().message();
  const std::size_t decode_peak = m.peak_bytes();
  EXPECT_LE(decode_peak, kDecodeHeapBound);
  EXPECT_GE(decode_peak, bins * sizeof(double)) << "the meter saw the values";
  std::printf("decode_model of the largest legitimate file (%zu bytes): peak heap %.1f MiB\n",
              file->size(), double(decode_peak) / double(kMiB));

  m.start();
  const BrdfTable table = decoded->table();
  EXPECT_LE(m.peak_bytes(), kTableHeapBound);
  std::printf("table(): peak heap %.1f MiB on top of the Model\n",
              double(m.peak_bytes()) / double(kMiB));
  EXPECT_EQ(table.count_not_measured(), kBinsPerChannel * kChannels);
  EXPECT_EQ(table.stored(2, kBinsPerChannel - 1), decoded->not_measured.values.back());
}

}  // namespace
}  // namespace cbrdf
