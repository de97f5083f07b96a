// SPDX-License-Identifier: MIT
#include "report/float16_baseline.h"

#include <algorithm>
#include <chrono>

#include "report/float16.h"

namespace cbrdf::report {
namespace {
constexpr double kMaxHalf = 65504.0;  // the largest finite IEEE half
}  // namespace

Expected<Float16Result> float16_round_trip(const BrdfTable& table, int zstd_level) {
  using Clock = std::chrono::steady_clock;
  auto t0 = Clock::now();
  std::vector<std::uint8_t> halves(kChannels * kBinsPerChannel * 2);
  std::size_t k = 0;
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      // Saturate: a near-mirror peak can exceed the half range, and infinity would poison
      // every error metric.
      const double v = std::min(table.physical(c, i), kMaxHalf);
      const std::uint16_t h = float_to_half(float(v));
      halves[k++] = std::uint8_t(h & 0xFF);
      halves[k++] = std::uint8_t(h >> 8);
    }
  }
  const double convert_s = std::chrono::duration<double>(Clock::now() - t0).count();
  CBRDF_ASSIGN_OR_RETURN(auto z, zstd_round_trip(halves, zstd_level));
  Float16Result r{std::move(z), BrdfTable()};
  r.compressed.encode_s += convert_s;
  t0 = Clock::now();
  k = 0;
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i, k += 2) {
      const auto h = std::uint16_t(halves[k] | (halves[k + 1] << 8));
      r.decoded.set_physical(c, i, double(half_to_float(h)));
    }
  }
  r.compressed.decode_s += std::chrono::duration<double>(Clock::now() - t0).count();
  return r;
}

}  // namespace cbrdf::report
