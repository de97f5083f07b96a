// SPDX-License-Identifier: MIT
// The fitter's side of the copula family table (copula/registry.h holds the decoder's): a row
// per family, in the same order, with what only the encoder needs. A static_assert holds the two
// tables to the same families, so a family added to the decoder's table without its fitter's row
// does not build.
#pragma once

#include <cstddef>
#include <iterator>

#include "cbrdf/copula_family.h"
#include "copula/registry.h"

namespace cbrdf::internal {

struct FitFamilyRow {
  CopulaFamily id;
  // Whether `--family auto` fits it; auto keeps the first of equal objectives in table order.
  bool in_auto;
  // fit_parameter's coarse scan for a start (the objective can have shallow local minima far
  // from independence): these parameters besides independence, those outside the search range
  // skipped.
  double scan[2];
};

inline constexpr FitFamilyRow kFitFamilies[] = {
    {CopulaFamily::kIndependence, false, {0.0, 0.0}},  // no parameter: nothing to fit
    // Independence inside the range: both sides.
    {CopulaFamily::kFrank, true, {-5.0, 0.4}},
    // Independence at the range's lower end: above it.
    {CopulaFamily::kClayton, true, {0.5, 4.0}},
    {CopulaFamily::kGumbel, true, {1.5, 5.0}},
    {CopulaFamily::kJoe, true, {1.5, 5.0}},
};

constexpr bool fit_families_cover_registry() {
  if (std::size(kFitFamilies) != kCopulaFamilyCount) return false;
  for (std::size_t i = 0; i < kCopulaFamilyCount; ++i) {
    if (kFitFamilies[i].id != kCopulaFamilies[i].id) return false;
  }
  return true;
}
static_assert(fit_families_cover_registry(),
              "every family in copula/registry.h needs its fitter's row here, in the same order");

// The fitter's row of a family; null for an unknown one.
constexpr const FitFamilyRow* fit_family_row(CopulaFamily family) {
  const std::size_t i = std::size_t(family);
  return i < std::size(kFitFamilies) ? &kFitFamilies[i] : nullptr;
}

// The family of a mixture's added components under `--family auto` (the paper's).
inline constexpr CopulaFamily kAutoMixtureFamily = CopulaFamily::kFrank;

}  // namespace cbrdf::internal
