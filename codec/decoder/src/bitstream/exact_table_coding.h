// SPDX-License-Identifier: MIT
// The exact table coding's layout and rules that its reader (exact_table.cc) and the encoder's
// writer (exact_table_writer.cc) share: the predictors, the residual's zigzag and size, and the
// contexts of the size symbols.
#pragma once

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>

#include "cbrdf/brdf_table.h"

namespace cbrdf::internal::exact_coding {

inline constexpr std::uint8_t kMethodPredictive = 1;
inline constexpr int kRowsPerChannel = kThetaHBins * kThetaDBins;
inline constexpr std::size_t kTotalBins = std::size_t{kChannels} * kBinsPerChannel;
inline constexpr std::size_t kBitmapBytes = kTotalBins / 8;
inline constexpr std::size_t kPlaneStride = std::size_t{kThetaDBins} * kPhiDBins;  // theta_h step
inline constexpr int kContexts = 8;
inline constexpr int kSymbols = 128;

// Difference orders along (theta_h, theta_d, phi_d); one is chosen per row.
struct Order {
  int h, d, p;
};
inline constexpr std::array<Order, 16> kPredictors = {{{0, 0, 1},
                                                       {0, 0, 2},
                                                       {1, 0, 1},
                                                       {1, 0, 2},
                                                       {1, 1, 1},
                                                       {0, 1, 2},
                                                       {2, 0, 2},
                                                       {2, 0, 3},
                                                       {3, 0, 3},
                                                       {3, 0, 4},
                                                       {4, 0, 3},
                                                       {4, 0, 4},
                                                       {1, 2, 3},
                                                       {2, 1, 3},
                                                       {1, 1, 3},
                                                       {2, 2, 2}}};
inline constexpr int kMaxOrder = 4;

inline std::uint64_t zigzag(std::uint64_t r) {
  return (r << 1) ^ (std::uint64_t{0} - (r >> 63));
}
inline std::uint64_t unzigzag(std::uint64_t z) {
  return (z >> 1) ^ (std::uint64_t{0} - (z & 1));
}
inline int bit_length(std::uint64_t z) {
  return 64 - std::countl_zero(z);
}

// The symbol stream of a residual's size s = a + b, a and b the sizes at the previous bin and at
// the same (theta_d, phi_d) one theta_h plane back.
inline int context_of(int a, int b) {
  static constexpr std::array<int, kContexts - 1> kUpper = {8, 20, 28, 34, 40, 46, 54};
  const int s = a + b;
  int ctx = 0;
  while (ctx < kContexts - 1 && s >= kUpper[std::size_t(ctx)]) ++ctx;
  return ctx;
}

inline bool is_exception(std::uint64_t bits) {
  return (bits >> 63) != 0;
}

}  // namespace cbrdf::internal::exact_coding
