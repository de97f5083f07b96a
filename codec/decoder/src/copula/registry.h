// SPDX-License-Identifier: MIT
// The one table of copula families (internal): a row per family holds all the decoder knows of
// it. Names, ids, the command's and the C API's lists, the ranges a file may hold, the grids that
// fit and evaluate a family and the sampler's conditionals all come from here.
//
// Adding a family is its mathematics (a final Copula in copula/<name>.cc, its instance declared
// below) plus one row here and its fitter's row in the encoder's table (fit/fit_families.h, which
// a static_assert holds to this one). Ids are the rows' positions: a row is only ever appended.
#pragma once

#include <cstddef>
#include <iterator>
#include <limits>
#include <memory>
#include <numbers>
#include <string_view>

#include "cbrdf/copula_family.h"
#include "copula/copula.h"
#include "density/frank_grid.h"

namespace cbrdf {

namespace internal {
class GridCopula;
}  // namespace internal
namespace internal {
struct ProductForm;
}  // namespace internal

struct Component;
struct CopulaFamilyRow;

namespace internal {
// The one instance of each family (copula/<name>.cc).
const Copula& independence_copula();
const Copula& frank_copula();
const Copula& clayton_copula();
const Copula& gumbel_copula();
const Copula& joe_copula();
}  // namespace internal

namespace internal {
// Grids with a closed form of their own (density/grid_copula.cc); the other families use the
// general Archimedean grid (density/archimedean_grid.cc).
std::unique_ptr<GridCopula> make_independence_grid(const CopulaFamilyRow& row);
std::unique_ptr<GridCopula> make_frank_grid(const CopulaFamilyRow& row);
}  // namespace internal

namespace internal {
// Families whose density factors per axis as the evaluator's kernels need (eval/product_form.cc).
ProductForm independence_product_form(const Component& c);
ProductForm frank_product_form(const Component& c);
}  // namespace internal

struct CopulaFamilyRow {
  CopulaFamily id;         // the id in .cbrdf files: never changes
  std::string_view name;   // the command's, the reports' and the C API's spelling
  std::string_view title;  // in messages ("Frank")
  // Density, CDF, generator and the conditionals the sampler inverts (copula.h).
  const Copula& (*copula)();
  // The parameter range the encoder searches, which is also what a file may hold (spec 4.2),
  // inside the copula's 3-D domain: beyond it the dependence is so strong that no BRDF slice
  // wants it, and evaluating it takes the slow log-sum paths.
  double search_lo, search_hi;
  // The density over a tensor grid of CDF values (fitting and evaluation); null: the general
  // Archimedean grid.
  std::unique_ptr<internal::GridCopula> (*grid)(const CopulaFamilyRow& row);
  // Parameters below this the own grid does not evaluate accurately: evaluation takes the general
  // Archimedean grid there (a Model in memory may hold any parameter of the domain).
  double grid_lo = -std::numeric_limits<double>::infinity();
  // The evaluator's product form of a component of the family (eval/product_form.h), whose tables
  // the vector kernels read without a per-sample call; null, or a form that is not ok: the
  // evaluator sums the family's grid per bin.
  internal::ProductForm (*product_form)(const Component& c) = nullptr;

  // Whether the family has a parameter at all (independence has not).
  constexpr bool has_parameter() const { return search_lo != search_hi; }
};

inline constexpr CopulaFamilyRow kCopulaFamilies[] = {
    {CopulaFamily::kIndependence, "independence", "independence", &internal::independence_copula,
     0.0, 0.0, &internal::make_independence_grid, -std::numeric_limits<double>::infinity(),
     &internal::independence_product_form},
    // The fitted Frank parameters of the MERL data stay within |theta| < 10; FrankGrid's terms
    // underflow below kFrankGridMinAlpha.
    {CopulaFamily::kFrank, "frank", "Frank", &internal::frank_copula, internal::kFrankGridMinAlpha,
     std::numbers::ln2, &internal::make_frank_grid, internal::kFrankGridMinAlpha,
     &internal::frank_product_form},
    {CopulaFamily::kClayton, "clayton", "Clayton", &internal::clayton_copula, 0.0, 50.0, nullptr},
    {CopulaFamily::kGumbel, "gumbel", "Gumbel", &internal::gumbel_copula, 1.0, 20.0, nullptr},
    {CopulaFamily::kJoe, "joe", "Joe", &internal::joe_copula, 1.0, 20.0, nullptr},
};

inline constexpr std::size_t kCopulaFamilyCount = std::size(kCopulaFamilies);

// Ids are dense, so that an id is a row's index and the largest is the count less one.
constexpr bool copula_family_ids_dense() {
  for (std::size_t i = 0; i < kCopulaFamilyCount; ++i) {
    if (std::size_t(kCopulaFamilies[i].id) != i) return false;
  }
  return true;
}
static_assert(copula_family_ids_dense(), "a family's id must be its row's index");
static_assert(kCopulaFamilyCount <= 256, "ids are one byte in files");

// The row of a family; null for a value no row has (validate raw bytes with family_valid).
constexpr const CopulaFamilyRow* family_row(CopulaFamily family) {
  const std::size_t i = std::size_t(family);
  return i < kCopulaFamilyCount ? &kCopulaFamilies[i] : nullptr;
}

}  // namespace cbrdf
