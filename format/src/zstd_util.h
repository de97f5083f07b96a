// SPDX-License-Identifier: MIT
// One-shot zstd with the safety rules of the container: a frame must declare its content size,
// that size must equal the size the chunk declared, and nothing is allocated beyond it.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "cbrdf/status.h"

namespace cbrdf {

// One frame with the content size in its header (ZSTD_compress writes it).
Expected<std::vector<std::uint8_t>> zstd_compress(std::span<const std::uint8_t> src, int level);

// Decompresses `src`, which must be exactly one frame declaring exactly `expected_bytes` of
// content, into a buffer of that size. Messages carry no location; callers add it.
Expected<std::vector<std::uint8_t>> zstd_decompress_exact(std::span<const std::uint8_t> src,
                                                          std::size_t expected_bytes);

}  // namespace cbrdf
