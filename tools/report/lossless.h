// SPDX-License-Identifier: MIT
// General-purpose compressors as baselines: sizes and times of a verified round trip.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "cbrdf/status.h"

namespace cbrdf::report {

struct Compressed {
  std::vector<std::uint8_t> bytes;
  double encode_s = 0.0;
  double decode_s = 0.0;
};

// zstd at the given level (1..22), single-threaded. The result is decompressed and compared with
// the input; a mismatch is kInternal.
Expected<Compressed> zstd_round_trip(std::span<const std::uint8_t> data, int level);
// xz (.xz container, CRC64 check) at the given preset (0..9), single-threaded, verified likewise.
Expected<Compressed> xz_round_trip(std::span<const std::uint8_t> data, std::uint32_t preset);

// Plain zstd decompression of a single frame whose content size is recorded.
Expected<std::vector<std::uint8_t>> zstd_decompress(std::span<const std::uint8_t> frame);

}  // namespace cbrdf::report
