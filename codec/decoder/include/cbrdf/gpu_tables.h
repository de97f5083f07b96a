// SPDX-License-Identifier: MIT
/// @file
/// What a GPU shader samples to evaluate a Model: the evaluator's float32 tables
/// (ModelEvaluator::eval_f32's) as flat float32 arrays, plus two optional MERL-grid volumes (the
/// terms without a product form, and the residual layer). The npm package's packGpuTables
/// (tools/npm/glsl.mjs) repacks them into the textures its cbrdfGlsl reads (spec/gpu-tables.md,
/// whose layout is versioned apart from this one); the viewer's browser test holds that shader
/// to eval_f32.
///
/// `tables` (integers are exact, all below 2^24):
/// - [0] layout version (kGpuTablesLayout); [1] slices S; [2] volume mode: 0 none, 1 residual
///   (log1p units), 2 the exact table (lossless residual: physical values replace the model);
///   [3] the residual's knee (stored units); [4] 1 when `generic` holds terms; [5..15] 0;
/// - [16 + j], j < 90: the slice of theta_d bin j;
/// - [106 + 8 s ..]: slice s: theta_d begin, end, R (slots per channel), G (groups of 4 slots),
///   and the offsets (into this array) of its theta_h rows (91), theta_d rows (width + 1), phi_d
///   rows (181) and constants (G x 28), each a multiple of 4 (zeros pad the header).
/// - A row is G groups of 12: the g of 4 slots, their w, their y; slot q = channel R + component
///   sits in group q / 4 at lane q % 4. Constants per group: k, a0, a1, a2, b0, b1, b2, 4 lanes
///   each. The value of a slot at interpolated terms is k g1 g2 g3 (b0 + b1 Y + b2 W) /
///   (a0 + a1 Y + a2 W)^3 with W = w1 w2 w3, Y = y1 + w1 y2 + w1 w2 y3.
///
/// `generic` and `residual` (3 x 90 x 90 x 180 each, or empty): RGB interleaved per MERL bin, bin
/// index (theta_h 90 + theta_d) 180 + phi_d. `generic`: the physical values of the components
/// without the product form (Clayton, Gumbel, Joe, Frank below -200) summed per bin; `residual`:
/// the residual layer's value per bin (log1p units) or, in mode 2, the exact table's physical
/// values with 0 at bins not measured.
#pragma once

#include <cstddef>
#include <vector>

#include "cbrdf/model.h"

namespace cbrdf {

/// The version of the layout gpu_tables() writes (tables[0]).
inline constexpr int kGpuTablesLayout = 1;

/// A model's GPU tables (layout in the file's description).
struct GpuTables {
  std::vector<float> tables;    ///< header, slice map, slice descriptors, rows and constants
  std::vector<float> generic;   ///< empty when every component has a product form
  std::vector<float> residual;  ///< empty without a residual layer
  /// The three arrays' size in bytes: what a GPU holds for the model.
  std::size_t bytes() const {
    return (tables.size() + generic.size() + residual.size()) * sizeof(float);
  }
};

/// Builds the tables of a decoded model as the evaluator builds its own, rounded to float as
/// eval_f32 rounds them.
GpuTables gpu_tables(const Model& model);

/// The copula density of a component over the (theta_h, phi_d) bins at bin j of its slice's
/// theta_d range (0 <= j < width), on the grid bin values use: 90 x 180 values, row-major by
/// theta_h. All 1 for the independence copula; empty when j is out of range.
std::vector<double> copula_density_plane(const Component& component, int j);

}  // namespace cbrdf
