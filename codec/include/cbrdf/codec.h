// SPDX-License-Identifier: MIT
/// @file
/// Model <-> .cbrdf bytes: the lossy codec's public entry points (spec/container.md).
///
/// encode_model quantizes the marginal tables (the only lossy step); families, parameters, the
/// scale K, slice bounds, the not-measured mask and its stored values are kept bit for bit.
/// decode_model and inspect_container run the same full validation.
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

/// How encode_model() writes a model (the container side of EncoderSettings).
struct ContainerSettings {
  /// Bits per marginal code, 6..16: the quality knob. 12 keeps the tone-mapped sphere PSNR within
  /// 0.02 dB of the unquantized model on the 20 real materials, at 4.4 to 6.7 KB per file.
  int bits = 12;
  int zstd_level = 19;         ///< 1..22: the effort knob
  std::string source_name;     ///< recorded in the metadata chunk (e.g. the .binary's file name)
  bool write_metadata = true;  ///< the ancillary 'mETA' chunk: source, encoder, settings
  /// The container's coding. kAuto: version 1.3 (BASE: parameters as binary32, range-coded
  /// marginal tables) when its model chunks are smaller than 1.2's, else the lowest of 1.0-1.2
  /// that holds the model, byte for byte as before. kV12: never 1.3. kV13: 1.3 whenever the
  /// parameters have binary32 forms (always for fitted models). kV12 here keeps this struct's
  /// files as before; encoder_settings (the command, the report) defaults to kAuto.
  enum class Format {
    kAuto,  ///< 1.3 where smaller
    kV12,   ///< the 1.0-1.2 chunks only
    kV13    ///< 1.3 whenever possible
  };
  Format format = Format::kV12;  ///< the coding written
  /// What 'mETA' holds when written.
  enum class Metadata {
    kShort,  ///< the source and encoder only (bits are in the file's coding already)
    kFull    ///< source, encoder, bits and zstd level
  };
  Metadata metadata = Metadata::kFull;  ///< what 'mETA' holds
};

/// Fails with kInvalidArgument when the settings or the model are outside what a file can hold
/// (unknown family, parameter outside its family's domain, K < 0 or not finite, slices not
/// contiguous over [0, 90), marginal tables of the wrong size or with negative or non-finite
/// masses, mask values that are not negative, or a values list of the wrong length).
Expected<std::vector<std::uint8_t>> encode_model(const Model& model,
                                                 const ContainerSettings& settings);

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
  double residual_knee = 0;       ///< in stored units (spec 4.6)
  std::size_t residual_escapes = 0;                           ///< bins it stores exactly
  std::vector<std::pair<std::string, std::string>> metadata;  ///< mETA keys in file order
};

/// Validates exactly as decode_model does (every chunk is decoded) and describes the file.
Expected<ContainerInfo> inspect_container(std::span<const std::uint8_t> bytes);

/// Valid parameter domain of each family as this codec checks it (documented in the spec).
bool copula_parameter_valid(CopulaFamily family, double theta);

}  // namespace cbrdf
