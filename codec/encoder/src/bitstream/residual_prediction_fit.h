// SPDX-License-Identifier: MIT
// RESD's predicted codes (spec 4.6, "Predicted codes", predictor 3), the writer's side: the
// coefficients' fit, the codes the stream carries and the coefficients as stored
// (bitstream/residual_prediction.h has the format and the reader).
#pragma once

#include <cstdint>

#include "bitstream/residual_prediction.h"
#include "cbrdf/model.h"

namespace cbrdf {
class ByteWriter;
}  // namespace cbrdf

namespace cbrdf::internal {

// Writes the coefficients as stored: for c = R, G, B, for g = 0 .. groups - 1: a (R), or a, b, g
// (G and B), each an i16.
void write_prediction(ByteWriter& w, const CodePrediction& p);

// The writer's coefficients for codes q (kMaskBits, 0 at not-measured bins): per group, a
// weighted least-absolute-deviation fit (iteratively reweighted least squares) on every fourth
// phi_d bin, kept only where it lowers sum log2(1 + |code|) (the size the range coder's exponents
// pay) there by 1% or more. All zero when prediction does not help.
CodePrediction fit_prediction(const std::int32_t* q, const NotMeasured& mask,
                              const Residual& residual);

// The codes the stream carries, r = q - P (encoder). False when an r falls outside
// -2^28..2^28 (the writer then keeps predictor 2).
bool predict_codes(const std::int32_t* q, const NotMeasured& mask, const Residual& residual,
                   const CodePrediction& p, std::int32_t* r);

}  // namespace cbrdf::internal
