// SPDX-License-Identifier: MIT
// The residual layer's encoder (container 1.2, spec/container.md 4.6): the source against the
// base model exactly as a decoder rebuilds it, quantized under the bound, written, decoded again
// and checked on every measured bin.
#pragma once

#include "cbrdf/encoder.h"

namespace cbrdf::internal {

// The knee k the writer uses for a source table: 1e-4 (stored units), or for a table whose
// values all lie below 1 (scaled down: no real material), 1e-4 times its peak's power of two
// over 2^13.
double residual_knee(const BrdfTable& source);

// `result` holds the base file (bytes, bits) and the fitted model; on success its bytes are the
// file with the residual layer and its model carries the residual. Fails with kInternal if the
// decoded file misses the bound after the fix-up (it cannot: escapes store those bins exactly).
// For searches that try several bounds on one base (residual_rate.cc): `base_table`, when given,
// is the base file's decoded table (Model::table() of decode_model(result->bytes)), so it is not
// rebuilt per try; `decoded`, when given, receives the decoded table of the file written (the
// check's own decode), so the caller need not decode it again.
Status add_residual(const BrdfTable& source, const EncoderSettings& settings, EncodeResult* result,
                    const BrdfTable* base_table = nullptr, BrdfTable* decoded = nullptr);

// The largest |log1p(decoded / k) - log1p(source / k)| over measured bins, stored values, k the
// residual's knee; the bins whose error exceeds their bound (Residual::bound_at) go to
// `violations` (when given), in increasing order.
double max_log_error(const BrdfTable& source, const BrdfTable& decoded, const Residual& residual,
                     std::vector<std::uint32_t>* violations = nullptr);

// RESD mode 2's row shifts (ResidualSettings::row_steps) for the bound `max_error`: per row r =
// 90 theta_h + theta_d, round(log2(sqrt(W_max / W_r))) clamped to kRowStepShiftCap and to the
// format's largest bound, with W_r the row's solid-angle measure times the sum over its phi_d
// bins of cos(theta_i) cos(theta_o) (0 below the horizon). High-rate theory: a step
// proportional to 1 / sqrt(weight) minimises the weighted squared error at a given rate.
// With level multipliers (modes 3 and 4), the largest m: no bound m x max_error x 2^shift exceeds
// the format's.
std::vector<std::uint8_t> residual_row_shifts(double max_error, int largest_multiplier = 1);
inline constexpr int kRowStepShiftCap = 6;

}  // namespace cbrdf::internal
