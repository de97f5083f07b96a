// SPDX-License-Identifier: MIT
#include "cbrdf/brdf_table.h"

namespace cbrdf {

std::size_t BrdfTable::count_not_measured() const {
  std::size_t n = 0;
  // NaN counts as not measured, as measured() says: only values >= 0 are measurements.
  for (double v : stored_) n += v >= 0.0 ? 0 : 1;
  return n;
}

}  // namespace cbrdf
