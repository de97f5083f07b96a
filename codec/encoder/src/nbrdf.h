// SPDX-License-Identifier: MIT
// The NBRDF weight format of Sztrajman et al., "Neural BRDF Representation and Importance
// Sampling" (CGF 2021), described in data/measured/README.md: a 6-21-21-3 network with ReLU after
// the two hidden layers, whose output exp(y) - 1 is the physical BRDF value (R, G, B). The
// built-in measured samples are such networks fitted to MERL measurements.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "cbrdf/brdf_table.h"
#include "cbrdf/status.h"

namespace cbrdf::internal {

inline constexpr int kNbrdfInputs = 6, kNbrdfHidden = 21, kNbrdfOutputs = 3;
inline constexpr std::size_t kNbrdfFloats = kNbrdfInputs * kNbrdfHidden + kNbrdfHidden +
                                            kNbrdfHidden * kNbrdfHidden + kNbrdfHidden +
                                            kNbrdfHidden * kNbrdfOutputs + kNbrdfOutputs;  // 675
inline constexpr std::size_t kNbrdfBytes = 4 * kNbrdfFloats;

// The weights, widened to double once; w[input][output] as the file stores them.
struct NbrdfNet {
  std::array<std::array<double, kNbrdfHidden>, kNbrdfInputs> w1{};
  std::array<double, kNbrdfHidden> b1{};
  std::array<std::array<double, kNbrdfHidden>, kNbrdfHidden> w2{};
  std::array<double, kNbrdfHidden> b2{};
  std::array<std::array<double, kNbrdfOutputs>, kNbrdfHidden> w3{};
  std::array<double, kNbrdfOutputs> b3{};
};

// Parses exactly kNbrdfBytes little-endian float32 values. Fails with kTruncated (too short),
// kCorrupt (too long) or kNumeric (a NaN or infinite weight, named by its layer and position);
// `name` starts each message.
Expected<NbrdfNet> parse_nbrdf(std::span<const std::uint8_t> bytes, std::string_view name);

// The network's physical RGB value for input x = (h, d), the half and difference vectors. Each
// sum runs bias first, then inputs in order, in double: the result depends only on the
// arguments. A slightly negative output (a fit's undershoot where the material reflects almost
// nothing) is returned as 0, since a physical BRDF value is never negative.
void eval_nbrdf(const NbrdfNet& net, const std::array<double, kNbrdfInputs>& x, double rgb[3]);

// The network's input at a bin's grid angles: h = (sin th, 0, cos th),
// d = (sin td cos pd, sin td sin pd, cos td).
std::array<double, kNbrdfInputs> nbrdf_input(double theta_h, double theta_d, double phi_d);

// The network on the MERL grid, below-horizon bins stored -1 (see tabulate_grid). The same bytes
// for any thread count. Fails with kNumeric if the network overflows at some bin.
Expected<BrdfTable> tabulate_nbrdf(const NbrdfNet& net);

}  // namespace cbrdf::internal
