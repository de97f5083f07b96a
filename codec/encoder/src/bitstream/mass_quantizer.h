// SPDX-License-Identifier: MIT
// The writer's quantizers of marginal probability-mass tables (spec/container.md, "MARG"): masses
// to codes on a stored log range (bitstream/quantize.h, the decoder's, holds the codes' meaning
// and their reconstruction).
#pragma once

#include <optional>
#include <span>

#include "bitstream/quantize.h"

namespace cbrdf {

// The log of the masses' sum (nonpositive ones count as 0), or nothing when none is positive.
// Finite even where the plain sum overflows (masses near the double maximum): then summed
// relative to the largest mass. Both quantizers once coded such a table as all zeros.
std::optional<double> log_mass_sum(std::span<const double> masses);

// Masses must be finite and >= 0 (the caller checks). The table is scaled to sum 1 first, which
// the decoder's renormalization reproduces; an all-zero table gives all codes 0.
QuantizedTable quantize_masses(std::span<const double> masses, int bits);

// quantize_masses with the range on the grid; *range receives H and D.
QuantizedTable quantize_masses_on_grid(std::span<const double> masses, int bits, GridRange* range);

// Largest relative error |m'/m - 1| of any nonzero mass after decoding, for this table's range:
// rounding moves each log mass by at most step/2 and renormalization by at most another step/2,
// so the bound is e^step - 1 with step = (hi - lo) / (2^bits - 2).
double relative_error_bound(const QuantizedTable& table, int bits);

}  // namespace cbrdf
