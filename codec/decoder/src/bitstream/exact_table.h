// SPDX-License-Identifier: MIT
// The exact (lossless) coding of a whole BrdfTable (spec: "Exact table coding"): every stored
// value's IEEE bit pattern comes back bit for bit, NaN payloads, -0.0 and not-measured values
// included. Each channel is predicted from already decoded neighbours by integer differences of
// the bit patterns (one predictor chosen per row of phi_d), and the residuals are coded as a
// size symbol (zstd, split by context) and raw low bits. Decoding uses integer operations only.
// The reader; the writer is the encoder's (codec/encoder/src/bitstream/exact_table_writer.h).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "cbrdf/brdf_table.h"
#include "cbrdf/status.h"

namespace cbrdf::internal {

// kCorrupt (with a message naming the stream, or the bin) for anything encode_exact_table could
// not have written, data ending early included; allocations are bounded by the table's fixed size
// whatever the header says.
Expected<BrdfTable> decode_exact_table(std::span<const std::uint8_t> bytes);

}  // namespace cbrdf::internal
