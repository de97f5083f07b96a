// SPDX-License-Identifier: MIT
// The exact (lossless) coding of a whole BrdfTable, the writer (bitstream/exact_table.h has the
// format and its reader): every stored value's IEEE bit pattern comes back bit for bit.
#pragma once

#include <cstdint>
#include <vector>

#include "cbrdf/brdf_table.h"

namespace cbrdf::internal {

// zstd level of the compressed streams; decoding does not depend on it.
inline constexpr int kExactTableZstdLevel = 16;

std::vector<std::uint8_t> encode_exact_table(const BrdfTable& table,
                                             int zstd_level = kExactTableZstdLevel);

}  // namespace cbrdf::internal
