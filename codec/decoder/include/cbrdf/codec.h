// SPDX-License-Identifier: MIT
/// @file
/// .cbrdf bytes -> Model: the decoder's public entry points (spec/container.md). The writer,
/// encode_model, is the encoder library's (cbrdf/container_writer.h). decode_model and
/// inspect_container run the same full validation.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "cbrdf/container.h"
#include "cbrdf/model.h"
#include "cbrdf/status.h"

namespace cbrdf {

struct ContainerInfo;
/// Decodes a .cbrdf file's bytes. Full validation; errors name the chunk tag and its byte offset.
/// With info, also what inspect_container gives, from the same single pass. Cost: 1.5 to 2.5 ms
/// CPU without a residual layer (the first call in a process about 4 ms more: the below-horizon
/// reference mask, built once); a residual layer's 4,374,000 codes are decoded on every call,
/// 15 to 55 ms (cbrdf/cbrdf_decode.h, Cost).
Expected<Model> decode_model(std::span<const std::uint8_t> bytes, ContainerInfo* info = nullptr);

/// Reads a .cbrdf file (a regular file or a path naming an open descriptor such as /dev/stdin; at
/// most kMaxContainerBytes) and decodes it as decode_model does. Errors: kInvalidArgument (an empty
/// path), kNotFound, kIo, kLimit (reading), then decode_model's; messages start with the path.
Expected<Model> decode_model_file(const std::string& path, ContainerInfo* info = nullptr);

/// decode_model, then the full MERL-resolution table (Model::table()).
Expected<BrdfTable> decode_table(std::span<const std::uint8_t> bytes);

/// The parameters of one slice as the file stores them.
struct SliceParams {
  int theta_d_begin = 0;                         ///< first theta_d bin
  int theta_d_end = 0;                           ///< one past the last
  std::array<CopulaFamily, kChannels> family{};  ///< of the first component, per channel
  std::array<double, kChannels> theta{};         ///< its copula parameter
  std::array<double, kChannels> scale{};         ///< of the first component
  std::array<int, kChannels> components{};       ///< 1, or more in a mixture (version 1.1)
};

/// What `cbrdf info` shows: the chunk layout and the decoded header, parameters and metadata.
struct ContainerInfo {
  ContainerLayout layout;                        ///< version and chunks
  std::array<double, kChannels> colour_scale{};  ///< the header's per-channel scale
  int bits = 0;                                  ///< bits per marginal code
  std::vector<SliceParams> slices;               ///< in theta_d order
  std::size_t not_measured_bins = 0;             ///< set bits of the mask over all channels
  bool mask_relative_to_horizon = false;         ///< coded as the XOR with the below-horizon mask
  bool per_bin_values = false;                   ///< one stored value per not-measured bin
  /// 'RESD' (1.2): -1 absent, 0 bounded log residual, 1 exact, 2 row steps, 3 interpolated levels
  int residual_mode = -1;
  double residual_max_error = 0;  ///< its bound on |log1p(decoded / knee) - log1p(source / knee)|
  double residual_min_error = 0;  ///< modes 2, 3: the finest row's bound (else residual_max_error)
  /// How modes 0 and 2-4 code their codes (RESD's predictor byte, spec 4.6): 0 zigzag varints, 1
  /// the same after the previous phi_d bin, 2 range coded, 3 range coded after a prediction across
  /// theta_h slabs and channels; -1 in mode 1 and without a residual layer.
  int residual_coding = -1;
  double residual_knee = 0;                                   ///< in stored units (spec 4.6)
  std::size_t residual_escapes = 0;                           ///< bins it stores exactly
  std::vector<std::pair<std::string, std::string>> metadata;  ///< mETA keys in file order
};

/// Validates exactly as decode_model does (every chunk is decoded) and describes the file.
Expected<ContainerInfo> inspect_container(std::span<const std::uint8_t> bytes);

/// Valid parameter domain of each family as this codec checks it (documented in the spec).
bool copula_parameter_valid(CopulaFamily family, double theta);

}  // namespace cbrdf
