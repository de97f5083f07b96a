// SPDX-License-Identifier: MIT
// Rate control's forecast of a model's file size before it is fitted. A file stores a header and,
// per slice, channel and component, marginal tables of about the same size, so its bytes at a bit
// depth grow about linearly with the components of a slice count and with the slice count. The
// forecast lets the search skip mixture fits (the costly step) whose file cannot fit the target.
#pragma once

#include <map>
#include <optional>
#include <utility>

namespace cbrdf::internal {

class BytePredictor {
 public:
  // The bytes of a fitted (slice count, component count) at the fewest bits.
  void add(int slices, int components, double bytes);
  // The forecast for a setting not fitted yet, from settings that were; none when too few are known
  // to extrapolate.
  std::optional<double> predict(int slices, int components) const;

 private:
  std::optional<double> known(int slices, int components) const;
  std::map<std::pair<int, int>, double> bytes_;  // (slices, components) -> bytes
};

}  // namespace cbrdf::internal
