// SPDX-License-Identifier: MIT
#include "report/lossless.h"

#include <lzma.h>
#include <zstd.h>

#include <algorithm>
#include <chrono>
#include <string>

namespace cbrdf::report {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

Status mismatch(const char* what) {
  return error(ErrorCode::kInternal,
               std::string(what) + " round trip did not reproduce its input (a library bug?)");
}

}  // namespace

Expected<std::vector<std::uint8_t>> zstd_decompress(std::span<const std::uint8_t> frame) {
  const unsigned long long size = ZSTD_getFrameContentSize(frame.data(), frame.size());
  if (size == ZSTD_CONTENTSIZE_ERROR || size == ZSTD_CONTENTSIZE_UNKNOWN) {
    return error(ErrorCode::kCorrupt, "zstd frame without a content size");
  }
  std::vector<std::uint8_t> out(size);
  const std::size_t n = ZSTD_decompress(out.data(), out.size(), frame.data(), frame.size());
  if (ZSTD_isError(n) || n != out.size()) {
    return error(ErrorCode::kCorrupt,
                 std::string("zstd decompression failed: ") +
                     (ZSTD_isError(n) ? ZSTD_getErrorName(n) : "short output"));
  }
  return out;
}

Expected<Compressed> zstd_round_trip(std::span<const std::uint8_t> data, int level) {
  Compressed r;
  auto t0 = Clock::now();
  r.bytes.resize(ZSTD_compressBound(data.size()));
  const std::size_t n =
      ZSTD_compress(r.bytes.data(), r.bytes.size(), data.data(), data.size(), level);
  if (ZSTD_isError(n)) {
    return error(ErrorCode::kInternal, std::string("zstd: ") + ZSTD_getErrorName(n));
  }
  r.bytes.resize(n);
  r.encode_s = since(t0);
  t0 = Clock::now();
  auto back = zstd_decompress(r.bytes);
  r.decode_s = since(t0);
  if (!back.ok()) return back.status();
  if (!std::equal(back->begin(), back->end(), data.begin(), data.end())) return mismatch("zstd");
  return r;
}

Expected<Compressed> xz_round_trip(std::span<const std::uint8_t> data, std::uint32_t preset) {
  Compressed r;
  auto t0 = Clock::now();
  r.bytes.resize(lzma_stream_buffer_bound(data.size()));
  std::size_t pos = 0;
  lzma_ret ret = lzma_easy_buffer_encode(preset, LZMA_CHECK_CRC64, nullptr, data.data(),
                                         data.size(), r.bytes.data(), &pos, r.bytes.size());
  if (ret != LZMA_OK) {
    return error(ErrorCode::kInternal,
                 "xz: compression failed (lzma code " + std::to_string(int(ret)) + ")");
  }
  r.bytes.resize(pos);
  r.encode_s = since(t0);
  t0 = Clock::now();
  std::vector<std::uint8_t> back(data.size());
  std::uint64_t memlimit = UINT64_MAX;
  std::size_t in_pos = 0, out_pos = 0;
  ret = lzma_stream_buffer_decode(&memlimit, 0, nullptr, r.bytes.data(), &in_pos, r.bytes.size(),
                                  back.data(), &out_pos, back.size());
  r.decode_s = since(t0);
  if (ret != LZMA_OK || out_pos != back.size()) {
    return error(ErrorCode::kInternal,
                 "xz: decompression failed (lzma code " + std::to_string(int(ret)) + ")");
  }
  if (back != std::vector<std::uint8_t>(data.begin(), data.end())) return mismatch("xz");
  return r;
}

}  // namespace cbrdf::report
