// SPDX-License-Identifier: MIT
/// @file
/// The encoder's settings as text, the way `cbrdf encode`, `cbrdf report` and Python take them
/// ("auto", "1.3", "visibility"), and their translation into EncoderSettings. Every problem is a
/// SettingProblem (cbrdf/encoder_settings.h) with the setting's neutral name, so each front end
/// words it with its own spelling of the option.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cbrdf/encoder.h"
#include "cbrdf/encoder_settings.h"

namespace cbrdf {

/// An "integer or auto" value: `--slices N|auto`, `--components K|auto`, `--bits B|auto`, the
/// report's sweep lists.
struct CountOrAuto {
  int count = 0;         ///< meaningless when is_auto
  bool is_auto = false;  ///< "auto" was given
};

/// `text` as an integer from lo to hi or, when allow_auto, "auto"; nullopt for anything else (no
/// sign, spaces or fraction).
std::optional<CountOrAuto> parse_count_or_auto(std::string_view text, int lo, int hi,
                                               bool allow_auto);

/// `text` as a finite decimal number ("0.01", "1e-3", "60"); nullopt for anything else (spaces,
/// a trailing unit, nan, inf).
std::optional<double> parse_number(std::string_view text);

/// A bits value of the report's sweep lists that stands for "auto".
inline constexpr int kAutoBits = 0;

/// The encoder's settings as text, with `cbrdf encode`'s defaults. Each field's neutral name
/// (SettingProblem::setting) is its own name, except `placement` ("--slice-placement").
struct EncoderOptions {
  std::string slices = "6";             ///< 1 to 90, or auto (count and boundaries from the data)
  std::string placement = "uniform";    ///< uniform or adaptive
  std::string components = "1";         ///< 1 to kMaxComponents, or auto (up to kAutoMaxComponents)
  std::string family = "frank";         ///< frank, clayton, gumbel, joe, independence or auto
  std::string mixture_copulas = "fit";  ///< fit or independence (FitSettings::mixture_copulas)
  std::string bits = "auto";            ///< 6 to 16, or auto (AutoBitsSettings)
  int zstd_level = ContainerSettings{}.zstd_level;  ///< 1 to 22
  std::string loss = "linear";                      ///< linear, cosine or log
  int threads = 0;               ///< fitting threads, 0 (one per core, thread_limit()) to 256
  bool naive_marginals = false;  ///< the paper's marginals (missing bins as 0)
  std::string source_name;       ///< recorded in the container's metadata
  double max_error = 0;          ///< the residual layer's bound (ResidualSettings); 0: none
  bool lossless = false;         ///< the residual layer makes the decoded table exact
  /// How max_error bounds the layer: "one" (every bin within it) or "visibility" (it bounds the
  /// most visible rows: target_residual_settings, what a rate target writes).
  std::string residual_steps = "one";
  /// auto (1.3 where smaller), 1.2 (the 1.0-1.2 chunks only) or 1.3 (ContainerSettings::Format)
  std::string format_version = "auto";
  std::string metadata = "short";  ///< none, short (source, encoder) or full (and bits, zstd level)
};

/// What parse_options() made of EncoderOptions.
struct ParsedOptions {
  EncoderSettings settings;              ///< meaningful only when problems is empty
  std::vector<SettingProblem> problems;  ///< every option that cannot be read or encoded
};

/// The settings `options` stand for: each value read (a problem for text that is none of the
/// option's values) and then the whole checked by validate().
ParsedOptions parse_options(const EncoderOptions& options);

/// parse_options() as settings, or kInvalidArgument naming every problem in `spell`'s words
/// (settings_status(); none: the neutral names, which are EncoderOptions' fields).
Expected<EncoderSettings> encoder_settings(const EncoderOptions& options,
                                           const SettingSpelling& spell = {});

/// The residual layer a bound (0: none), lossless or visibility steps ask for: what
/// `--max-error E [--residual-steps visibility]` and `--lossless` write, for every front end.
ResidualSettings residual_request(double max_error, bool lossless, bool visibility_steps);

/// Which residual options and rate targets (target_bytes, target_psnr) a caller gave.
struct GivenResidualOptions {
  bool target = false;          ///< target_bytes or target_psnr
  bool max_error = false;       ///< max_error
  bool lossless = false;        ///< lossless
  bool residual_steps = false;  ///< residual_steps
};

/// A target chooses the residual layer itself: the problem with a bound, lossless or residual
/// steps given beside one, else nullopt. (Visibility steps without a bound are validate()'s.)
std::optional<SettingProblem> residual_option_conflict(const GivenResidualOptions& given);

/// Sets a slice count (fixed: explicit boundaries cleared, auto_slices off; auto: chosen from the
/// data) and a component count (auto: up to kAutoMaxComponents) on `settings`: what
/// parse_options() does with slices and components, and what rate control does for each
/// candidate it tries.
void set_counts(CountOrAuto slices, CountOrAuto components, FitSettings* settings);

}  // namespace cbrdf
