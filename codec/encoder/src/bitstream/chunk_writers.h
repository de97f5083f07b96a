// SPDX-License-Identifier: MIT
// The chunk payloads' writers (spec/container.md section 4), one file per chunk beside the
// encoder's container writer (write_model.cc); their readers, and the constants and rules both
// share, are the decoder's (bitstream/chunks.h). Writers assume a model that encode_model has
// validated.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "bitstream/chunks.h"
#include "bitstream/range_coder.h"
#include "cbrdf/model.h"

namespace cbrdf {

// Whether any slice channel has further components (a version 1.1 file).
bool has_mixtures(const Model& model);
// The lowest minor version that holds the model: 2 with a residual layer, 1 with mixtures, else 0.
std::uint16_t container_minor(const Model& model);

std::vector<std::uint8_t> encode_header_chunk(const Model& model, bool compact);
// The binary32 BASE holds for a parameter (spec 4.8) with K as BASE stores it: the nearest, or its
// neighbour towards the inside of the family's range; nullopt when neither is inside it.
std::optional<float> parameter_f32(std::uint8_t family, double theta, double scale);
// Whether K keeps binary32's relative precision (2^-24) as a binary32: 0, or a normal binary32
// after rounding to nearest. A table scaled by 1e-50 has K near 1e-47, which binary32 rounds to
// 0 (issue 40: such files decoded to zeros).
bool scale_fits_f32(double k);
// Whether BASE holds the model's K as binary64 (flags bit 1): some K does not fit binary32.
bool base_wide_scales(const Model& model);
// The K a BASE chunk holds for k: binary32's nearest, or k itself when its K are binary64.
double base_scale(double k, bool wide);
// Version 1.3: MODL and MARG in one chunk; nullopt when a parameter has no binary32 inside its
// family's range (the writer then uses the 1.2 chunks).
std::optional<std::vector<std::uint8_t>> encode_base_chunk(const Model& model, int bits);

// How the BASE writer chooses a marginal table's codes (encoder only: the decoder reads any codes
// and its ratios depend on D alone, spec 4.7). Exposed for the tests.
namespace base_codes {
// A table's exact code positions: D the grid span holding its log masses (the smallest, or up to
// kSpanSearch units more where plain rounding then errs least on the mass-squared-weighted log
// masses: what a linear image sees), the largest
// mass at the top code (exact, as 1.2's range made it), position[i] in [1, top] (0 for a zero
// mass), weight[i] the mass over the largest raised to kWeightPower (what a rendered image sees
// of a relative error in bin i: 0.45 is the display curve's exponent, 1 / 2.2, so the tails a
// tone-mapped image shows keep their codes; at 1, the linear image's view, the rounding moved
// them freely and cost up to 1.5 dB tone-mapped at 6 bits, e.g. nickel 47.46 dB in 954 B against
// 48.95 dB in 929 B at 0.45).
struct Positions {
  std::uint32_t span_units = 0;
  std::vector<double> position, weight;
};
inline constexpr double kWeightPower = 0.45;
inline constexpr std::uint32_t kSpanSearch = 8;
Positions positions(std::span<const double> masses, int bits);
// Plain rounding of every position.
std::vector<std::uint32_t> rounded(const Positions& p);
// Rate-distortion cost of codes under a predictor from the given contexts: sum of weight x (code -
// position)^2 (in code steps) plus lambda x the range coder's bits.
struct Predicting {
  int mode = 0;
  const std::vector<std::uint32_t>* ref_codes = nullptr;
  std::uint32_t ref_span = 0;
  std::int64_t first = 0, top = 0;
};
double rd_cost(const Positions& p, const std::vector<std::uint32_t>& codes, const Predicting& how,
               std::array<internal::SIntContexts, 3> contexts, double lambda);
// Each code the neighbour of its position (floor or ceiling) with the least weighted error plus
// lambda x its bits from the contexts as they adapt, in coding order; then whichever of these
// codes and the plain rounding costs less (rd_cost): never more than plain rounding.
std::vector<std::uint32_t> rd_rounded(const Positions& p, const Predicting& how,
                                      const std::array<internal::SIntContexts, 3>& contexts,
                                      double lambda);
// The writer's lambda, per squared log mass per bit (a table's lambda in squared code steps is
// this over its step squared): 12 to 17% fewer marginal bytes for at most 0.16 dB on real
// materials (docs/benchmarks.md).
inline constexpr double kWriterLambda = 3e-5;
double writer_lambda();
}  // namespace base_codes
std::vector<std::uint8_t> encode_model_chunk(const Model& model);
std::vector<std::uint8_t> encode_marginals_chunk(const Model& model, int bits);
std::vector<std::uint8_t> encode_mask_chunk(const NotMeasured& mask);
// range_coding: the file is version 1.3 or later, so the codes may be range coded (the writer
// takes that or the 1.2 coding, whichever is smaller after zstd).
std::vector<std::uint8_t> encode_residual_chunk(const Model& model, bool range_coding);
std::vector<std::uint8_t> encode_metadata_chunk(
    const std::vector<std::pair<std::string, std::string>>& entries);

}  // namespace cbrdf
