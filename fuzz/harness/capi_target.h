// SPDX-License-Identifier: MIT
// fuzz_capi: the C API as a renderer uses it. cbrdf_model_open_memory on the input (checksums
// repaired first, as fuzz_decode does, so mutations reach the payloads), then on what opens:
// cbrdf_model_get_info, cbrdf_model_eval and cbrdf_model_eval_batch at direction pairs chosen from
// the input's hash, cbrdf_model_sample_batch and cbrdf_model_pdf. Every value, pdf and sample
// weight must be finite and >= 0 (spec 4.6's residual limit and 4.2's parameter ranges promise
// it), the batch must equal the single evaluations bit for bit, a drawn wi must be a unit vector
// above the horizon, and a failure must carry a real error code and message.
//
// Speed: the sampler builds a table per outgoing direction it meets (the model evaluated over a
// grid of wi), which was 80% of this target's time with 48 random wo per input; and a residual
// layer costs 50 ms to seconds to decode under the sanitizers. So one input in kCapiFullEvery (by
// the input's hash) samples at 48 distinct wo and opens the file whole; the others sample the 48
// (u1, u2) at one wo (one table) and open the file without its RESD chunk (without_chunk,
// decode_target.h; fuzz_decode keeps it for more inputs). The replay test runs every file in full.
#pragma once

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "cbrdf/cbrdf_c.h"
#include "common.h"
#include "decode_target.h"

namespace cbrdf::fuzz {

inline constexpr int kCapiPairs = 48;
inline constexpr std::uint64_t kCapiFullEvery = 32;

struct CapiOptions {
  bool always_full = false;  // the regression test: the whole file, 48 distinct wo
};

inline bool finite_nonnegative(double v) {
  return std::isfinite(v) && v >= 0.0;
}

inline Result run_capi(Bytes input, const CapiOptions& options = {}) {
  Result r;
  const bool full = options.always_full || input_hash(input) % kCapiFullEvery == 0;
  std::vector<std::uint8_t> bytes = repair_checksums(input);
  if (!full) bytes = without_chunk(std::move(bytes), kTagResidual);
  cbrdf_model* model = cbrdf_model_open_memory(bytes.data(), bytes.size());
  if (model == nullptr) {
    const cbrdf_status code = cbrdf_last_error_code();
    const char* message = cbrdf_last_error_message();
    r.reject(error(ErrorCode(code), message ? message : ""), "cbrdf_model_open_memory");
    r.check(code != CBRDF_OK, "cbrdf_model_open_memory returned NULL with CBRDF_OK");
    return r;
  }
  r.accept();
  cbrdf_model_info info{};
  info.struct_size = sizeof info;
  r.check(cbrdf_model_get_info(model, &info) == CBRDF_OK, "cbrdf_model_get_info failed");
  r.check(finite_nonnegative(info.residual_max_error) && info.residual_max_error <= 16.0 * 64,
          "residual_max_error " + std::to_string(info.residual_max_error) + " out of range");

  // Direction pairs spread over the hemisphere, from the input's hash (replays take the same).
  std::uint64_t state = input_hash(input) | 1;
  auto next = [&state] {
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    return double(state >> 11) * 0x1p-53;
  };
  auto direction = [&](double* w) {
    const double z = 1e-3 + (1 - 1e-3) * next(), phi = 6.283185307179586 * next();
    const double s = std::sqrt(1 - z * z);
    w[0] = s * std::cos(phi);
    w[1] = s * std::sin(phi);
    w[2] = z;
  };
  std::vector<double> wi(3 * kCapiPairs), wo(3 * kCapiPairs), rgb(3 * kCapiPairs),
      batch(3 * kCapiPairs), u(2 * kCapiPairs), drawn(3 * kCapiPairs), pdf(kCapiPairs),
      weight(3 * kCapiPairs), sample_wo(3 * kCapiPairs);
  for (int k = 0; k < kCapiPairs; ++k) {
    direction(&wi[3 * std::size_t(k)]);
    direction(&wo[3 * std::size_t(k)]);
    u[2 * std::size_t(k)] = next();
    u[2 * std::size_t(k) + 1] = next();
  }
  // The directions sampled from: the 48 wo, or the first one 48 times.
  for (std::size_t i = 0; i < sample_wo.size(); ++i) sample_wo[i] = wo[full ? i : i % 3];
  for (int k = 0; k < kCapiPairs; ++k) {
    const std::size_t o = 3 * std::size_t(k);
    r.check(cbrdf_model_eval(model, &wi[o], &wo[o], &rgb[o]) == CBRDF_OK, "cbrdf_model_eval");
    for (int c = 0; c < 3; ++c) {
      r.check(finite_nonnegative(rgb[o + std::size_t(c)]),
              "eval pair " + std::to_string(k) + ": " + std::to_string(rgb[o + std::size_t(c)]));
    }
  }
  r.check(
      cbrdf_model_eval_batch(model, kCapiPairs, wi.data(), wo.data(), batch.data(), 1) == CBRDF_OK,
      "cbrdf_model_eval_batch");
  r.check(std::memcmp(batch.data(), rgb.data(), batch.size() * sizeof(double)) == 0,
          "cbrdf_model_eval_batch differs from cbrdf_model_eval");
  const cbrdf_status sampled = cbrdf_model_sample_batch(
      model, kCapiPairs, sample_wo.data(), u.data(), drawn.data(), pdf.data(), weight.data(), 1);
  r.check(sampled == CBRDF_OK, "cbrdf_model_sample_batch failed");
  for (int k = 0; sampled == CBRDF_OK && k < kCapiPairs; ++k) {
    const std::size_t o = 3 * std::size_t(k);
    r.check(finite_nonnegative(pdf[std::size_t(k)]),
            "sample " + std::to_string(k) + " pdf " + std::to_string(pdf[std::size_t(k)]));
    for (int c = 0; c < 3; ++c) {
      r.check(
          finite_nonnegative(weight[o + std::size_t(c)]),
          "sample " + std::to_string(k) + " weight " + std::to_string(weight[o + std::size_t(c)]));
    }
    if (pdf[std::size_t(k)] > 0) {
      const double* w = &drawn[o];
      r.check(w[2] > 0 && std::abs(w[0] * w[0] + w[1] * w[1] + w[2] * w[2] - 1) < 1e-6,
              "sample " + std::to_string(k) + " wi is not a unit vector above the horizon");
      double p = -1;
      r.check(
          cbrdf_model_sample_pdf(model, w, &sample_wo[o], &p) == CBRDF_OK && finite_nonnegative(p),
          "cbrdf_model_sample_pdf at a drawn direction");
    }
  }
  cbrdf_model_free(model);
  return r;
}

}  // namespace cbrdf::fuzz
