// SPDX-License-Identifier: MIT
// The product form of a component (interp_tables.h): whether it has one and, if so, its slot
// constants and its per-axis terms (g, w, y) at the midpoint CDF of the axis's masses, as
// FrankGrid::prepare forms them. Shared by the evaluator's tables (interp_tables.cc) and the
// GPU tables (gpu_tables.cc, cbrdf/gpu_tables.h), which must agree to the last bit
// before the viewer rounds them to float.
#pragma once

#include <vector>

#include "cbrdf/model.h"
#include "eval/interp_tables.h"

namespace cbrdf::internal {

// Parameters are evaluated clamped to [-1e300, 1e300] (model.cc, spec/container.md).
inline constexpr double kMaxEvaluatedParameter = 1e300;

struct ProductForm {
  bool ok = false;  // false: the component is evaluated from its grid copula
  double t = 0, b = 0;
  SlotConstants<double> k{};
};

// The product form of c's family (its row's product_form hook in copula/registry.h):
// independence, and Frank at or above internal::kFrankGridMinAlpha, have one.
ProductForm product_form(const Component& c);

// Axis terms of masses `pdf` (their midpoint CDF) for a product form.
void axis_terms(const ProductForm& f, const std::vector<double>& pdf,
                std::vector<AxisTerms<double>>* out);

}  // namespace cbrdf::internal
