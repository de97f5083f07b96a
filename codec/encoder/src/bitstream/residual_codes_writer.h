// SPDX-License-Identifier: MIT
// RESD's range-coded codes (spec 4.6, "Range-coded codes"), the writer; bitstream/residual_codes.h
// has the reader.
#pragma once

#include <cstdint>
#include <vector>

#include "cbrdf/model.h"

namespace cbrdf::internal {

// The codes q (kMaskBits, channel-major MERL order) of the bins `mask` does not mark, coded.
std::vector<std::uint8_t> encode_residual_codes(const std::int32_t* q, const NotMeasured& mask);

}  // namespace cbrdf::internal
