// SPDX-License-Identifier: MIT
// The C API's test of a batch's directions in the usual case, that every one is usable: a file of
// its own so that cbrdf.wasm compiles it for speed while the rest of the C API is compiled for
// size (tools/wasm/CMakeLists.txt). Not installed.
#pragma once

#include <cstddef>

namespace cbrdf::internal {

// Whether every direction of n interleaved (x, y, z) pairs wi, wo is a finite unit vector
// (unit_direction's tolerance) or exactly (0, 0, 0), as the C API's per-direction check accepts
// them; the caller names the first that is not only when this is false.
bool eval_pairs_usable(const double* wi, const double* wo, std::size_t n);
bool eval_pairs_usable(const float* wi, const float* wo, std::size_t n);

}  // namespace cbrdf::internal
