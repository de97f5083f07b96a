// SPDX-License-Identifier: MIT
// A MERL table filled from a function of each bin's grid angles: what the analytic samples and the
// measured (neural) samples share.
#pragma once

#include <functional>
#include <string_view>

#include "cbrdf/brdf_table.h"
#include "cbrdf/coords.h"
#include "cbrdf/status.h"

namespace cbrdf::internal {

// fn(angles, rgb) writes the physical RGB value at a bin's grid angles (theta_h = (i/90)^2 90 deg,
// theta_d = j deg, phi_d = k deg, phi_h = 0). It must depend on nothing but its arguments: rows
// run in parallel, and each bin's value is the same for any thread count.
using GridFn = std::function<void(const HalfDiff& angles, double rgb[3])>;

// The table with fn's value in every bin above the horizon and the bins bin_below_horizon() names
// stored -1 in every channel, exactly as real MERL files are. Fails with kNumeric, naming `what`
// and the first such bin, when fn yields a non-finite value.
Expected<BrdfTable> tabulate_grid(const GridFn& fn, std::string_view what);

}  // namespace cbrdf::internal
