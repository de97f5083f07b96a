// SPDX-License-Identifier: MIT
// RESD's writer (spec 4.6): the residual layer's payload, with the predictor and coding of the
// codes that make the chunk smallest (zigzag varints under predictor 0 or 1, or in version 1.3
// range coded as they are or after a prediction across slabs and channels).
#include <algorithm>
#include <array>
#include <cmath>

#include "bitstream/chunk_writers.h"
#include "bitstream/exact_table_writer.h"
#include "bitstream/residual_codes_writer.h"
#include "bitstream/residual_prediction.h"
#include "bitstream/residual_prediction_fit.h"
#include "byte_writer.h"
#include "zstd_util.h"

namespace cbrdf {
namespace {

// The zigzag varints of the measured bins' codes under a predictor.
std::vector<std::uint8_t> code_stream(const Model& model, std::uint8_t predictor) {
  ByteWriter w;
  const std::int32_t* q = model.residual.codes.data();
  for (int c = 0; c < kChannels; ++c) {
    for (std::size_t i = 0; i < kBinsPerChannel; ++i) {
      if (model.not_measured.test(c, i)) continue;
      const std::int64_t d =
          q[std::size_t(c) * kBinsPerChannel + i] - varint_code_prediction(q, c, i, predictor);
      w.varint32(zigzag(std::int32_t(d)));
    }
  }
  return w.take();
}

// Order-0 entropy of a byte stream, in bits: what zstd's literal coding approaches.
double entropy_bits(const std::vector<std::uint8_t>& s) {
  std::array<std::size_t, 256> n{};
  for (std::uint8_t b : s) ++n[b];
  double bits = 0;
  for (std::size_t k : n) {
    if (k > 0) bits -= double(k) * std::log2(double(k) / double(s.size()));
  }
  return bits;
}

// The payload with the codes as given (range-coded predictors: their u32 length first, after the
// coefficients of predictor 3).
std::vector<std::uint8_t> residual_payload(const Residual& res, std::uint8_t predictor,
                                           const std::vector<std::uint8_t>& codes,
                                           const internal::CodePrediction* prediction = nullptr) {
  ByteWriter w;
  // Mode 3 always carries row shifts (check_residual: all 0 for one step).
  w.u8(res.middle_steps()      ? kResidualModeLevelSteps
       : res.interpolated()    ? kResidualModeInterp
       : res.row_shift.empty() ? kResidualModeLog
                               : kResidualModeRows);
  w.u8(predictor);
  w.u16(0);
  w.f64(res.max_error);
  w.f64(res.step);
  w.f64(res.knee);
  w.u32(std::uint32_t(res.escapes.size()));
  if (!res.row_shift.empty()) w.bytes(res.row_shift);
  if (res.interpolated()) {
    w.u8(res.levels);
    w.u8(res.fine_multiplier);
    for (int l = 1; res.middle_steps() && l < res.levels; ++l) {
      w.u8(res.middle_multipliers[std::size_t(l - 1)]);
    }
  }
  if (predictor == kResidualPredictorRangePredicted) internal::write_prediction(w, *prediction);
  if (predictor != kResidualPredictorNone && predictor != kResidualPredictorPhi) {
    w.u32(std::uint32_t(codes.size()));
  }
  w.bytes(codes);
  std::uint64_t next = 0;
  for (const ResidualEscape& e : res.escapes) {
    w.varint32(std::uint32_t(e.bin - next));
    w.f64(e.stored);
    next = std::uint64_t(e.bin) + 1;
  }
  return w.take();
}

// What the chunk will take in the file: the payload or its zstd frame, whichever is smaller (as
// write_container stores it).
std::size_t stored_size(const std::vector<std::uint8_t>& payload) {
  Expected<std::vector<std::uint8_t>> z = zstd_compress(payload, kResidualZstdLevel);
  return z.ok() ? std::min(z->size(), payload.size()) : payload.size();
}

}  // namespace

std::vector<std::uint8_t> encode_residual_chunk(const Model& model, bool range_coding) {
  const Residual& res = model.residual;
  if (res.exact) {
    ByteWriter w;
    w.u8(kResidualModeExact);
    w.bytes(internal::encode_exact_table(*res.exact));
    return w.take();
  }
  // The predictor whose stream has the lower order-0 entropy (ties: none).
  std::vector<std::uint8_t> none = code_stream(model, kResidualPredictorNone);
  std::vector<std::uint8_t> phi = code_stream(model, kResidualPredictorPhi);
  const bool use_phi = entropy_bits(phi) < entropy_bits(none);
  std::vector<std::uint8_t> varints = residual_payload(
      res, use_phi ? kResidualPredictorPhi : kResidualPredictorNone, use_phi ? phi : none);
  if (!range_coding) return varints;
  std::vector<std::uint8_t> coded =
      residual_payload(res, kResidualPredictorRange,
                       internal::encode_residual_codes(res.codes.data(), model.not_measured));
  std::size_t best = stored_size(varints);
  std::vector<std::uint8_t>* chosen = &varints;
  if (const std::size_t n = stored_size(coded); n < best) {
    best = n;
    chosen = &coded;
  }
  // Predictor 3 where the fit finds anything to predict and the chunk comes out smaller.
  std::vector<std::uint8_t> predicted;
  const internal::CodePrediction prediction =
      internal::fit_prediction(res.codes.data(), model.not_measured, res);
  if (prediction.any()) {
    std::vector<std::int32_t> r(kMaskBits);
    if (internal::predict_codes(res.codes.data(), model.not_measured, res, prediction, r.data())) {
      predicted = residual_payload(res, kResidualPredictorRangePredicted,
                                   internal::encode_residual_codes(r.data(), model.not_measured),
                                   &prediction);
      if (stored_size(predicted) < best) chosen = &predicted;
    }
  }
  return std::move(*chosen);
}

}  // namespace cbrdf
