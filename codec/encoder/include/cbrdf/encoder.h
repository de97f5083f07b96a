// SPDX-License-Identifier: MIT
// One-call encoding of whole tables: fit + quantize + container (decode_table, the way back, is
// the decoder's: codec.h).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cbrdf/brdf_table.h"
#include "cbrdf/codec.h"
#include "cbrdf/export.h"
#include "cbrdf/fit.h"
#include "cbrdf/model.h"
#include "cbrdf/status.h"

namespace cbrdf {

struct EncoderSettings {
  FitSettings fit;
  ContainerSettings container;
};

// An "integer or auto" option value: `--slices N|auto`, `--components K|auto`, the report's
// sweep lists.
struct CountOrAuto {
  int count = 0;  // meaningless when is_auto
  bool is_auto = false;
};

// `text` as an integer from lo to hi or, when allow_auto, "auto"; nullopt for anything else (no
// sign, spaces or fraction). Callers word the message: an option and a sweep list name it apart.
CBRDF_EXPORT std::optional<CountOrAuto> parse_count_or_auto(std::string_view text, int lo, int hi,
                                                            bool allow_auto);

// The encoder's user-facing options, as `cbrdf encode` takes them (and `cbrdf report` sets them).
struct EncoderOptions {
  std::string slices = "6";             // 1 to 90, or auto (count and boundaries from the data)
  std::string placement = "uniform";    // uniform or adaptive
  std::string components = "1";         // 1 to kMaxComponents, or auto (up to kAutoMaxComponents)
  std::string family = "frank";         // frank, clayton, gumbel, joe, independence or auto
  int bits = ContainerSettings{}.bits;  // 6 to 16
  int level = ContainerSettings{}.zstd_level;  // zstd level, 1 to 22
  std::string loss = "linear";                 // linear, cosine or log
  int threads = 0;                             // fitting threads (0: one per core)
  bool naive_marginals = false;                // the paper's marginals (missing bins as 0)
  std::string source_name;                     // recorded in the container's metadata
};

// The settings the options stand for. kInvalidArgument names the option and its valid values in
// one line ("--slices must be 1 to 90 or auto, not '0'"), the same wording for every caller.
CBRDF_EXPORT Expected<EncoderSettings> encoder_settings(const EncoderOptions& options);

// Sets a slice count (fixed: explicit boundaries cleared, auto_slices left as it is; auto: chosen
// from the data) and a
// component count (auto: up to kAutoMaxComponents) on `settings`: what encoder_settings does with
// --slices and --components, and what rate control does for each candidate it tries.
CBRDF_EXPORT void set_counts(CountOrAuto slices, CountOrAuto components, FitSettings* settings);

struct EncodeResult {
  std::vector<std::uint8_t> bytes;  // the .cbrdf file
  Model model;                      // as fitted, before quantization
  FitReport report;
};

// Fits the model to the table and writes it as a .cbrdf container.
CBRDF_EXPORT Expected<EncodeResult> encode_table(const BrdfTable& table,
                                                 const EncoderSettings& settings);

}  // namespace cbrdf
