// SPDX-License-Identifier: MIT
#include "zstd_util.h"

#include <zstd.h>

#include <memory>
#include <string>

namespace cbrdf {
namespace {

struct DCtxDeleter {
  void operator()(ZSTD_DCtx* d) const { ZSTD_freeDCtx(d); }
};
struct CCtxDeleter {
  void operator()(ZSTD_CCtx* c) const { ZSTD_freeCCtx(c); }
};

}  // namespace

Expected<std::vector<std::uint8_t>> zstd_compress(std::span<const std::uint8_t> src, int level) {
  std::unique_ptr<ZSTD_CCtx, CCtxDeleter> cctx(ZSTD_createCCtx());
  if (!cctx) return error(ErrorCode::kInternal, "zstd: cannot create a compression context");
  std::vector<std::uint8_t> out(ZSTD_compressBound(src.size()));
  const std::size_t n =
      ZSTD_compressCCtx(cctx.get(), out.data(), out.size(), src.data(), src.size(), level);
  if (ZSTD_isError(n)) {
    return error(ErrorCode::kInternal,
                 std::string("zstd compression failed: ") + ZSTD_getErrorName(n));
  }
  out.resize(n);
  return out;
}

Expected<std::vector<std::uint8_t>> zstd_decompress_exact(std::span<const std::uint8_t> src,
                                                          std::size_t expected_bytes) {
  // Every size is checked before the output buffer exists: the declared content size first,
  // then the frame's own extent, so a frame cannot claim more than the chunk allows.
  const unsigned long long content = ZSTD_getFrameContentSize(src.data(), src.size());
  if (content == ZSTD_CONTENTSIZE_ERROR) {
    return error(ErrorCode::kCorrupt, "the stored bytes are not a zstd frame");
  }
  if (content == ZSTD_CONTENTSIZE_UNKNOWN) {
    return error(ErrorCode::kCorrupt, "the zstd frame does not declare its content size");
  }
  if (content != expected_bytes) {
    return error(ErrorCode::kCorrupt, "the zstd frame declares " + std::to_string(content) +
                                          " bytes of content but the chunk declares " +
                                          std::to_string(expected_bytes));
  }
  const std::size_t frame = ZSTD_findFrameCompressedSize(src.data(), src.size());
  if (ZSTD_isError(frame)) {
    return error(ErrorCode::kCorrupt,
                 std::string("the zstd frame is damaged: ") + ZSTD_getErrorName(frame));
  }
  if (frame != src.size()) {
    return error(ErrorCode::kCorrupt, "the zstd frame ends after " + std::to_string(frame) +
                                          " of the " + std::to_string(src.size()) +
                                          " stored bytes");
  }
  std::unique_ptr<ZSTD_DCtx, DCtxDeleter> dctx(ZSTD_createDCtx());
  if (!dctx) return error(ErrorCode::kInternal, "zstd: cannot create a decompression context");
  std::vector<std::uint8_t> out(expected_bytes);
  const std::size_t n =
      ZSTD_decompressDCtx(dctx.get(), out.data(), out.size(), src.data(), src.size());
  if (ZSTD_isError(n)) {
    return error(ErrorCode::kCorrupt,
                 std::string("zstd decompression failed: ") + ZSTD_getErrorName(n));
  }
  if (n != expected_bytes) {
    return error(ErrorCode::kCorrupt, "zstd produced " + std::to_string(n) + " bytes instead of " +
                                          std::to_string(expected_bytes));
  }
  return out;
}

}  // namespace cbrdf
