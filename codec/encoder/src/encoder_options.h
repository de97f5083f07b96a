// SPDX-License-Identifier: MIT
// The encoder's options as the command, the report, Python and the C API spell them (strings
// such as "auto" and "1.3"), and their translation into EncoderSettings with one wording of every
// message. Internal: library users set EncoderSettings (cbrdf/encoder.h) directly.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "cbrdf/encoder.h"

namespace cbrdf {

// An "integer or auto" option value: `--slices N|auto`, `--components K|auto`, the report's
// sweep lists.
struct CountOrAuto {
  int count = 0;         //< meaningless when is_auto
  bool is_auto = false;  //< "auto" was given
};

// `text` as an integer from lo to hi or, when allow_auto, "auto"; nullopt for anything else (no
// sign, spaces or fraction). Callers word the message: an option and a sweep list name it apart.
std::optional<CountOrAuto> parse_count_or_auto(std::string_view text, int lo, int hi,
                                               bool allow_auto);

// EncoderOptions::bits for `--bits auto`.
inline constexpr int kAutoBits = 0;

// The encoder's user-facing options, as `cbrdf encode` takes them (and `cbrdf report` sets them).
struct EncoderOptions {
  std::string slices = "6";           //< 1 to 90, or auto (count and boundaries from the data)
  std::string placement = "uniform";  //< uniform or adaptive
  std::string components = "1";       //< 1 to kMaxComponents, or auto (up to kAutoMaxComponents)
  std::string family = "frank";       //< frank, clayton, gumbel, joe, independence or auto
  // Mixtures: fit or independence (FitSettings::mixture_copulas).
  std::string mixture_copulas = "fit";
  int bits = kAutoBits;  //< 6 to 16, or kAutoBits (the default: see AutoBitsSettings)
  int level = ContainerSettings{}.zstd_level;  //< zstd level, 1 to 22
  std::string loss = "linear";                 //< linear, cosine or log
  int threads = 0;                             //< fitting threads (0: one per core)
  bool naive_marginals = false;                //< the paper's marginals (missing bins as 0)
  std::string source_name;                     //< recorded in the container's metadata
  double max_error = 0;   //< the residual layer's bound (ResidualSettings); 0: none
  bool lossless = false;  //< the residual layer makes the decoded table exact
  // How max_error bounds the layer: "one" (every bin within it) or "visibility" (it bounds the
  // most visible rows; target_residual_settings, what --target-psnr writes).
  std::string residual_steps = "one";
  // auto (1.3 where smaller), 1.2 (the 1.0-1.2 chunks only) or 1.3 (ContainerSettings::Format)
  std::string format_version = "auto";
  std::string metadata = "short";  //< none, short (source, encoder) or full (and bits, zstd level)
};

// The settings the options stand for. kInvalidArgument names the option and its valid values in
// one line ("--slices must be 1 to 90 or auto, not '0'"), the same wording for every caller.
Expected<EncoderSettings> encoder_settings(const EncoderOptions& options);

// The residual layer a bound (0: none), lossless or visibility steps ask for, once checked: what
// `--max-error E [--residual-steps visibility]` and `--lossless` write, for every front end.
ResidualSettings residual_request(double max_error, bool lossless, bool visibility_steps);

// Which residual options and targets (--target-bytes, --target-psnr) a caller gave.
struct GivenResidualOptions {
  bool target = false;
  bool max_error = false;
  bool lossless = false;
  bool residual_steps = false;
};
// A target chooses the residual layer itself, and steps shape the layer a bound adds: the message
// for options that do not fit together (in the command's words; Python renames them), else
// nullopt.
std::optional<std::string> residual_option_conflict(const GivenResidualOptions& given);

// Sets a slice count (fixed: explicit boundaries cleared, auto_slices left as it is; auto: chosen
// from the data) and a
// component count (auto: up to kAutoMaxComponents) on `settings`: what encoder_settings does with
// --slices and --components, and what rate control does for each candidate it tries.
void set_counts(CountOrAuto slices, CountOrAuto components, FitSettings* settings);

}  // namespace cbrdf
