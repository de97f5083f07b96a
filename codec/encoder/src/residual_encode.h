// SPDX-License-Identifier: MIT
// The residual layer's encoder (container 1.2, spec/container.md 4.6): the source against the
// base model exactly as a decoder rebuilds it, quantized under the bound, written, decoded again
// and checked on every measured bin.
#pragma once

#include "cbrdf/encoder.h"

namespace cbrdf::internal {

// `result` holds the base file (bytes, bits) and the fitted model; on success its bytes are the
// file with the residual layer and its model carries the residual. Fails with kInternal if the
// decoded file misses the bound after the fix-up (it cannot: escapes store those bins exactly).
Status add_residual(const BrdfTable& source, const EncoderSettings& settings, EncodeResult* result);

// The largest |log1p(decoded / knee) - log1p(source / knee)| over measured bins, stored values;
// the bins whose error exceeds `bound` go to `violations` (when given), in increasing order.
double max_log_error(const BrdfTable& source, const BrdfTable& decoded, double knee,
                     double bound = 0, std::vector<std::uint32_t>* violations = nullptr);

}  // namespace cbrdf::internal
