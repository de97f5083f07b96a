// SPDX-License-Identifier: MIT
// The decode peak of spec/container.md section 7 ("Resource bounds"), measured on the files that
// reach it: every chunk at its maximum payload (the file of issue 40, refused), every chunk that
// may stand beside the others at its maximum (decompressed, then refused by the first payload
// reader), and the largest Model a file holds (every bin not measured with its own value in the
// largest MASK, and the residual layer's exact table), through decode_model and decode_table. Heap
// use is measured with the replaced operator new of heap_meter.h (this binary only; ASan allows the
// replacement, and the meter counts malloc_usable_size, which ASan reports too).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bitstream/chunk_writers.h"
#include "bitstream/exact_table_writer.h"
#include "cbrdf/codec.h"
#include "cbrdf/container.h"
#include "heap_meter.h"
#include "synthetic_model.h"
#include "zstd_util.h"

namespace cbrdf {
namespace {

using Bytes = std::vector<std::uint8_t>;
using Meter = testing::heap::Meter;
constexpr std::size_t kMiB = std::size_t{1} << 20;

// The bounds stated in spec/container.md section 7.
constexpr std::size_t kDecodeHeapBound = 192 * kMiB;  // decode_model, inspect_container
constexpr std::size_t kTableHeapBound = 192 * kMiB;   // decode_table (decode, then table())

double mib(std::size_t bytes) {
  return double(bytes) / double(kMiB);
}

// A zstd frame of `bytes` zeros, compressed once per size (the tests use the same few sizes).
const Bytes& zero_frame(std::uint32_t bytes) {
  static std::map<std::uint32_t, Bytes> frames;
  auto it = frames.find(bytes);
  if (it == frames.end()) {
    Expected<Bytes> frame = zstd_compress(Bytes(bytes, 0), 1);
    EXPECT_TRUE(frame.ok());
    it = frames.emplace(bytes, frame.ok() ? *frame : Bytes{}).first;
  }
  return it->second;
}

// A file of the given chunks, each a zstd frame of zeros declaring its tag's maximum payload.
Bytes zero_chunks_at_maximum(std::uint16_t minor, std::initializer_list<std::string_view> tags) {
  Bytes file = container_file_header(kContainerMajorVersion, minor);
  for (std::string_view tag : tags) {
    const std::uint32_t p = max_chunk_payload_bytes(tag);
    const Bytes& frame = zero_frame(p);
    if (uses_compact_framing(minor)) {
      append_compact_chunk(&file, tag, kChunkFlagZstd, frame, p);
    } else {
      append_raw_chunk(&file, tag, kChunkFlagZstd, frame, p);
    }
  }
  if (uses_compact_framing(minor)) {
    append_compact_end(&file);
  } else {
    append_raw_chunk(&file, kTagEnd, 0, {}, 0);
  }
  return file;
}

std::size_t sum_of_maxima(std::initializer_list<std::string_view> tags) {
  std::size_t sum = 0;
  for (std::string_view tag : tags) sum += max_chunk_payload_bytes(tag);
  return sum;
}

TEST(DecodeMemory, EveryChunkAtItsMaximumIsRefusedBeforeAnyPayloadIsDecompressed) {
  // Issue 40's file: every known chunk, BASE beside MODL and MARG, each declaring its maximum
  // payload in a few bytes of zstd (82 MiB of payloads, 83.2 MiB peak before they were refused).
  for (const std::uint16_t minor : {std::uint16_t{2}, std::uint16_t{3}}) {
    SCOPED_TRACE("version 1." + std::to_string(minor));
    const Bytes file = zero_chunks_at_maximum(
        minor,
        {kTagHeader, kTagModel, kTagMarginals, kTagBase, kTagMask, kTagResidual, kTagMetadata});
    ASSERT_LT(file.size(), 8192u);
    Meter m;
    m.start();
    Expected<Model> model = decode_model(file);
    ASSERT_FALSE(model.ok());
    EXPECT_EQ(model.status().code(), ErrorCode::kCorrupt) << model.status().message();
    EXPECT_NE(model.status().message().find("'BASE'"), std::string::npos)
        << model.status().message();
    std::printf("every chunk at its maximum (1.%d, %zu bytes): peak heap %.2f MiB\n", minor,
                file.size(), mib(m.peak_bytes()));
    EXPECT_LE(m.peak_bytes(), kDecodeHeapBound);
    EXPECT_LT(m.peak_bytes(), kMiB) << "no payload was decompressed";
  }
}

TEST(DecodeMemory, ResidualLayerInAnOldFileIsRefusedBeforeItsPayloadIsDecompressed) {
  const Bytes file = zero_chunks_at_maximum(
      1, {kTagHeader, kTagModel, kTagMarginals, kTagMask, kTagResidual, kTagMetadata});
  Meter m;
  m.start();
  Expected<ParsedContainer> pc = parse_container(file);
  ASSERT_FALSE(pc.ok());
  EXPECT_EQ(pc.status().code(), ErrorCode::kCorrupt) << pc.status().message();
  EXPECT_NE(pc.status().message().find("needs container version 1.2"), std::string::npos)
      << pc.status().message();
  EXPECT_LT(m.peak_bytes(), kMiB);
}

TEST(DecodeMemory, EveryChunkThatMayStandTogetherAtItsMaximumStaysWithinTheBound) {
  // The chunks one file may hold together, each at its maximum: parse_container decompresses them
  // all (the payload readers run after it), then HEAD's reader refuses 256 zero bytes.
  struct Case {
    std::uint16_t minor;
    std::initializer_list<std::string_view> tags;
  };
  const Case cases[] = {
      {3, {kTagHeader, kTagBase, kTagMask, kTagResidual, kTagMetadata}},
      {2, {kTagHeader, kTagModel, kTagMarginals, kTagMask, kTagResidual, kTagMetadata}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE("version 1." + std::to_string(c.minor));
    const Bytes file = zero_chunks_at_maximum(c.minor, c.tags);
    Meter m;
    m.start();
    Expected<Model> model = decode_model(file);
    ASSERT_FALSE(model.ok());
    std::printf(
        "chunks that may stand together at their maximum (1.%d, %zu bytes): peak heap "
        "%.2f MiB (payloads %.2f MiB)\n",
        c.minor, file.size(), mib(m.peak_bytes()), mib(sum_of_maxima(c.tags)));
    EXPECT_GE(m.peak_bytes(), sum_of_maxima(c.tags)) << "the meter saw every payload";
    EXPECT_LE(m.peak_bytes(), kDecodeHeapBound);
  }
}

// The largest MASK (spec 2.3): every bin not measured, as a bitmap, with one value per bin.
Bytes largest_mask_payload(const NotMeasured& mask) {
  Bytes p;
  p.reserve(16 + kMaskBytes + kMaskBits * 8);
  p.push_back(std::uint8_t(MaskReference::kNone));
  p.push_back(std::uint8_t(MaskForm::kBitmap));
  p.push_back(std::uint8_t(MaskValues::kPerBin));
  p.push_back(0);
  auto put = [&p](std::uint64_t v, int bytes) {
    for (int i = 0; i < bytes; ++i) p.push_back(std::uint8_t(v >> (8 * i)));
  };
  put(kMaskBits, 4);
  put(mask_hash(mask.bits), 8);
  p.insert(p.end(), kMaskBytes, 0xFF);
  std::uint64_t bits;
  std::memcpy(&bits, &mask.values[0], 8);
  for (std::size_t i = 0; i < kMaskBits; ++i) put(bits, 8);
  return p;
}

// The largest Model a valid file holds, in version 1.3: every bin not measured with its own stored
// value (the largest MASK, 35,538,766 bytes), and RESD mode 1's exact table with random
// not-measured values, so that its value stream is stored as it is (about 35 MB of RESD payload,
// what the 64 MiB file leaves beside MASK). The exact table decodes with the most it allocates:
// the payload, its value stream, the table and each channel's working values at once.
Bytes largest_model_file() {
  Model model = testing::make_model(testing::six_slices());
  model.not_measured = NotMeasured{};
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) model.not_measured.set(c, i);
  }
  model.not_measured.values.assign(kMaskBits, -1.0);
  const Bytes mask = largest_mask_payload(model.not_measured);
  EXPECT_EQ(mask.size(), 16 + kMaskBytes + kMaskBits * 8);
  BrdfTable table;
  std::uint64_t state = 0x9E3779B97F4A7C15ull;
  for (double& v : table.stored_values()) {
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    v = -1.0 - double(state >> 11) * 0x1p-53;
  }
  Bytes resd = {kResidualModeExact};
  const Bytes exact = internal::encode_exact_table(table, 1);
  resd.insert(resd.end(), exact.begin(), exact.end());
  table = BrdfTable{};
  std::optional<Bytes> base = encode_base_chunk(model, 10);
  EXPECT_TRUE(base.has_value());
  const std::vector<ChunkToWrite> chunks = {
      {std::string(kTagHeader), encode_header_chunk(model, true), false},
      {std::string(kTagBase), base.value_or(Bytes{}), true},
      {std::string(kTagMask), mask, true, 1},
      {std::string(kTagResidual), resd, true, 1},
  };
  Expected<Bytes> file = write_container(chunks, 1, 3);
  EXPECT_TRUE(file.ok()) << file.status().message();
  return file.ok() ? *file : Bytes{};
}

TEST(DecodeMemory, LargestModelDecodesWithinTheBounds) {
  const Bytes file = largest_model_file();
  ASSERT_FALSE(file.empty());
  ASSERT_LE(file.size(), kMaxContainerBytes);

  Meter m;
  m.start();
  Expected<Model> decoded = decode_model(file);
  ASSERT_TRUE(decoded.ok()) << decoded.status().message();
  const std::size_t decode_peak = m.peak_bytes();
  ASSERT_TRUE(decoded->residual.exact);
  EXPECT_EQ(decoded->not_measured.values.size(), kMaskBits);
  std::printf("decode_model of the largest Model (%zu bytes): peak heap %.2f MiB\n", file.size(),
              mib(decode_peak));
  EXPECT_GE(decode_peak, 3 * kMaskBits * sizeof(double))
      << "the meter saw the mask's values, the exact table and its value stream";
  EXPECT_LE(decode_peak, kDecodeHeapBound);
  decoded = Model{};

  m.start();
  Expected<BrdfTable> t = decode_table(file);
  ASSERT_TRUE(t.ok()) << t.status().message();
  std::printf("decode_table of the same file: peak heap %.2f MiB\n", mib(m.peak_bytes()));
  EXPECT_LE(m.peak_bytes(), kTableHeapBound);
  EXPECT_EQ(t->count_not_measured(), kMaskBits);
}

}  // namespace
}  // namespace cbrdf
