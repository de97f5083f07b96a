// SPDX-License-Identifier: MIT
#include "rate/byte_predictor.h"

#include <iterator>

namespace cbrdf::internal {

void BytePredictor::add(int slices, int components, double bytes) {
  bytes_[{slices, components}] = bytes;
}

std::optional<double> BytePredictor::known(int slices, int components) const {
  const auto it = bytes_.find({slices, components});
  if (it == bytes_.end()) return std::nullopt;
  return it->second;
}

std::optional<double> BytePredictor::predict(int slices, int components) const {
  if (auto b = known(slices, components)) return b;
  if (components > 1) {
    const auto prev = known(slices, components - 1);
    if (!prev) return std::nullopt;
    // Linear in components: the step the last component added.
    if (auto prev2 = known(slices, components - 2); prev2 && components > 2) {
      return *prev + (*prev - *prev2);
    }
    // One count known here: the relative step of another slice count at the same counts.
    for (const auto& [key, b] : bytes_) {
      if (key.second != components || key.first == slices) continue;
      if (auto other_prev = known(key.first, components - 1)) return *prev * b / *other_prev;
    }
    return std::nullopt;
  }
  // One component at a new slice count: linear through the two nearest smaller slice counts.
  // Slopes fall with the slice count (the header is shared), so this overestimates slightly.
  const auto below = bytes_.lower_bound({slices, 0});
  int found = 0;
  double s[2] = {0, 0}, b[2] = {0, 0};
  for (auto it = std::make_reverse_iterator(below); it != bytes_.rend() && found < 2; ++it) {
    if (it->first.second != 1) continue;
    s[found] = it->first.first;
    b[found] = it->second;
    ++found;
  }
  if (found < 2) return std::nullopt;
  return b[0] + (b[0] - b[1]) / (s[0] - s[1]) * (slices - s[0]);
}

}  // namespace cbrdf::internal
