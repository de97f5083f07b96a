// SPDX-License-Identifier: MIT
/// @file
/// Model -> .cbrdf bytes: the container writer (spec/container.md), the encoder library's.
///
/// encode_model quantizes the marginal tables (the only lossy step); families, parameters, the
/// scale K, slice bounds, the not-measured mask and its stored values are kept bit for bit. The
/// per-chunk writers sit beside their readers in the decoder's sources; this entry point is
/// linked only into the encoder, so a decoder-only program carries no writer.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cbrdf/model.h"
#include "cbrdf/status.h"

namespace cbrdf {

/// How encode_model() writes a model (the container side of EncoderSettings).
struct ContainerSettings {
  /// Bits per marginal code, 6..16: the quality knob. 12 keeps the tone-mapped sphere PSNR within
  /// 0.02 dB of the unquantized model on the 20 real materials, at 4.4 to 6.7 KB per file.
  /// encode_table() reads it only when EncoderSettings::auto_bits is off.
  int bits = 12;
  int zstd_level = 19;         ///< 1..22: the effort knob
  std::string source_name;     ///< recorded in the metadata chunk (e.g. the .binary's file name)
  bool write_metadata = true;  ///< the ancillary 'mETA' chunk: source, encoder, settings
  /// The container's coding. kAuto: version 1.3 (BASE: parameters as binary32, each K as binary32
  /// or, when one K has no normal binary32, all K as binary64; range-coded marginal tables) when
  /// its model chunks are smaller than 1.2's, else the lowest of 1.0-1.2 that holds the model,
  /// byte for byte as before. Both keep K at any scale. kV12: never 1.3. kV13: 1.3 whenever the
  /// parameters have binary32 forms (always for fitted models). The default is the command's.
  enum class Format {
    kAuto,  ///< 1.3 where smaller
    kV12,   ///< the 1.0-1.2 chunks only
    kV13    ///< 1.3 whenever possible
  };
  Format format = Format::kAuto;  ///< the coding written
  /// What 'mETA' holds when written.
  enum class Metadata {
    kShort,  ///< the source and encoder only (bits are in the file's coding already)
    kFull    ///< source, encoder, bits and zstd level
  };
  Metadata metadata = Metadata::kShort;  ///< what 'mETA' holds
};

/// Fails with kInvalidArgument when the settings or the model are outside what a file can hold
/// (unknown family, parameter outside its family's domain, K < 0 or not finite, slices not
/// contiguous over [0, 90), marginal tables of the wrong size or with negative or non-finite
/// masses, mask values that are not negative, or a values list of the wrong length).
Expected<std::vector<std::uint8_t>> encode_model(const Model& model,
                                                 const ContainerSettings& settings);

}  // namespace cbrdf
