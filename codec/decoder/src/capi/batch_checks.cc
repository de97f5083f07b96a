// SPDX-License-Identifier: MIT
#include "capi/batch_checks.h"

#include "cbrdf/model.h"

namespace cbrdf::internal {
namespace {

template <class T>
bool usable(const T* w) {
  T x = w[0], y = w[1], z = w[2];
  return zero_direction(x, y, z) || unit_direction(x, y, z);
}

template <class T>
bool all_usable(const T* wi, const T* wo, std::size_t n) {
  for (std::size_t k = 0; k < 3 * n; k += 3) {
    if (!usable(wi + k) || !usable(wo + k)) return false;
  }
  return true;
}

}  // namespace

bool eval_pairs_usable(const double* wi, const double* wo, std::size_t n) {
  return all_usable(wi, wo, n);
}

bool eval_pairs_usable(const float* wi, const float* wo, std::size_t n) {
  return all_usable(wi, wo, n);
}

}  // namespace cbrdf::internal
