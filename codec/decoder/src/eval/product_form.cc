// SPDX-License-Identifier: MIT
// product_form.h's functions. Compiled as every evaluator file (eval_internal.h): no errno from
// math functions, no FMA contraction, so the tables are the same on every target.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("no-math-errno", "no-trapping-math", "fp-contract=off")
#endif
#include "eval/product_form.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <vector>

#include "copula/registry.h"
#include "density/frank_grid.h"
#include "density/grid_copula.h"

namespace cbrdf::internal {

ProductForm independence_product_form(const Component& c) {
  ProductForm f;
  f.ok = true;
  f.k = {c.scale, 1, 0, 0, 1, 0, 0};
  return f;
}

ProductForm frank_product_form(const Component& c) {
  const double theta = std::clamp(c.theta, -kMaxEvaluatedParameter, kMaxEvaluatedParameter);
  if (theta == 0.0) return independence_product_form(c);
  ProductForm f;
  if (theta < internal::kFrankGridMinAlpha) return f;
  f.ok = true;
  f.t = -theta;
  f.b = -std::expm1(-f.t);
  const double et = std::exp(-f.t);
  constexpr double kLn2Lo = 2.319046813846299558e-17;  // as frank_grid.cc
  const double one_plus_b = -2.0 * std::expm1((theta - std::numbers::ln2) - kLn2Lo);
  const double r = f.t / f.b;
  const double k = c.scale * (r * r);
  if (f.t > 0) {
    f.k = {k, et, f.b, 0, 1, 0, f.b};  // 1 - h = e^{-t} + b Y, 1 + h = 1 + b W
  } else {
    f.k = {k, 1, 0, -f.b, one_plus_b, -f.b, 0};  // 1 - h = 1 - b W, 1 + h = (2 - e^{-t}) - b Y
  }
  return f;
}

ProductForm product_form(const Component& c) {
  const CopulaFamilyRow* row = family_row(c.family);
  return row && row->product_form ? row->product_form(c) : ProductForm{};
}

void axis_terms(const ProductForm& f, const std::vector<double>& pdf,
                std::vector<AxisTerms<double>>* out) {
  std::vector<double> u;
  internal::midpoint_cdf(pdf, &u);
  out->resize(pdf.size());
  for (std::size_t i = 0; i < pdf.size(); ++i) {
    AxisTerms<double>& a = (*out)[i];
    if (f.t == 0.0) {
      a = {pdf[i], 0, 0};
      continue;
    }
    const double x = u[i], e = std::exp(-f.t * x);
    a.g = pdf[i] * e;
    a.w = -std::expm1(-f.t * x) / f.b;
    a.y = -e * std::expm1(-f.t * (1.0 - x)) / f.b;
  }
}

}  // namespace cbrdf::internal
