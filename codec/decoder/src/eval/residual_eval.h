// SPDX-License-Identifier: MIT
// The residual layer (container 1.2, spec/container.md 4.6) as a stage after the copula model:
// on the table (ModelEvaluator::table) the normative per-bin reconstruction, and on continuous
// evaluation (eval, eval_f32, eval_batch) the residual interpolated trilinearly between the 8
// bins around the direction pair's grid position, applied in the same log1p domain. A model
// without a residual never reaches this stage, so it evaluates exactly as the base does.
// The lossless mode's exact table replaces the base: the table is it, and evaluation interpolates
// it (lookup_linear).
#pragma once

#include <cstddef>
#include <cstdint>

#include "cbrdf/model.h"

namespace cbrdf::internal {

// The normative reconstruction of one measured bin (spec 4.6), in stored (MERL file) units:
// y = log1p(base / k) + code * step, value = y > 0 ? expm1(y) k : 0, saturated at the largest
// double.
double apply_residual(double base_stored, std::int32_t code, double step, double knee);
// The same with the bin's residual given (Residual::value_at; code x step in modes 0 and 2).
double apply_residual_value(double base_stored, double residual, double knee);

// Applies a model's residual to the base table: every measured bin reconstructed, then the
// escapes' exact values. Not-measured bins are left as they are.
void apply_residual_to_table(const Model& model, BrdfTable* table);

class ResidualEval {
 public:
  // Reads the model's residual and mask; the model must outlive this object (the evaluator owns
  // its model).
  explicit ResidualEval(const Model& model);

  // ModelEvaluator::bin_value: the base model's physical value at a bin, corrected as the table
  // is (the normative reconstruction, escapes and the exact table included) where the bin is
  // measured; unchanged where it is not.
  double at_bin(int channel, std::size_t index, double physical) const;

  // rgb holds the base model's physical values at the pair and receives the final ones; nothing
  // changes when wi or wo is at or below the horizon.
  void apply(const Vec3& wi, const Vec3& wo, double rgb[3]) const;
  void apply(const float wi[3], const float wo[3], float rgb[3]) const;

  // This object and the residual it evaluates (held by the model): codes, rebuilt values, row
  // shifts, escapes and the exact table, all of which evaluation reads.
  std::size_t footprint_bytes() const;

 private:
  const Residual* residual_;
  const NotMeasured* mask_;
};

}  // namespace cbrdf::internal
