// SPDX-License-Identifier: MIT
/// @file
/// Checking EncoderSettings before an encode: one validate() that every front end (the C++ API,
/// the C API, `cbrdf encode`, `cbrdf report`, Python) calls, naming each bad setting in a neutral
/// vocabulary that the front end then spells its own way (`--max-error`, `max_error=`,
/// `settings.max_error`).
#pragma once

#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cbrdf/encoder.h"
#include "cbrdf/status.h"

namespace cbrdf {

/// The range of the residual layer's bound, ResidualSettings::max_error (0: no layer): the
/// format's limits (spec/container.md 4.6).
///@{
inline constexpr double kMinResidualBound = 1e-6;
inline constexpr double kMaxResidualBound = 16.0;
///@}

/// One setting that cannot be encoded.
struct SettingProblem {
  /// The setting's neutral name: the snake_case name of its field ("slices", "components",
  /// "family", "bits", "zstd_level", "loss", "threads", "max_error", "lossless",
  /// "residual_steps", "format_version", "metadata", "mixture_copulas", "placement",
  /// "slice_bounds", "target_psnr", "target_bytes").
  std::string setting;
  /// The rest of the sentence after the setting's name, e.g. "must be from 1e-06 to 16, not 20"
  /// (for max_error, whose 0 means no residual layer). Another setting it names is written as its
  /// neutral name in braces
  /// ("{max_error}"), which spell_problem() replaces with the front end's spelling.
  std::string message;

  /// Equal when both the setting and the message are.
  bool operator==(const SettingProblem&) const = default;
};

/// A front end's spelling of a neutral setting name: `--max-error` for the command,
/// `max_error=` for Python, `cbrdf_encode_settings.max_error` for the C API. An empty function
/// leaves the neutral names as they are.
using SettingSpelling = std::function<std::string(std::string_view setting)>;

/// The C++ API's spelling: the setting's member of EncoderSettings ("fit.slices",
/// "container.bits", "residual.max_error"), or the neutral name itself for a setting that is no
/// member of it ("target_psnr": RateTarget's).
std::string cxx_spelling(std::string_view setting);

/// Every problem of `settings`, in a fixed order (empty: they can be encoded). Checks the ranges
/// of every value the encoder reads (slice and component counts, explicit slice boundaries,
/// family, loss, bits unless chosen automatically, zstd level, threads, the residual bound and
/// the container's format and metadata) and the settings that do not fit together (a bound with
/// lossless, steps without a bound).
std::vector<SettingProblem> validate(const EncoderSettings& settings);

struct RateTarget;
/// Every problem of a rate target (cbrdf/rate_control.h): target_bytes 0 (none) or above 0 up to
/// the largest container, target_psnr 0 (none) or above 0 up to 1000 dB, the searched component
/// and slice counts within their ranges.
std::vector<SettingProblem> validate(const RateTarget& target);

/// `problem` as one sentence in a front end's words: "<spelled setting> <message>", with every
/// "{name}" in the message spelled too.
std::string spell_problem(const SettingProblem& problem, const SettingSpelling& spell);

/// kOk when `problems` is empty; else kInvalidArgument whose message is every problem's
/// spell_problem(), joined by "; ".
Status settings_status(std::span<const SettingProblem> problems, const SettingSpelling& spell);

}  // namespace cbrdf
