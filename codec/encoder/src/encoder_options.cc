// SPDX-License-Identifier: MIT
// The encoder's settings as text (cbrdf/encoder_options.h): reading each value, then validate().
#include "cbrdf/encoder_options.h"

#include <charconv>
#include <climits>
#include <cmath>

#include "bitstream/chunks.h"
#include "cbrdf/encoder.h"
#include "cbrdf/parallel.h"

namespace cbrdf {
namespace {

std::string quoted(std::string_view text) {
  return "'" + std::string(text) + "'";
}

// "must be V1, V2 or V3, not 'x'"
SettingProblem not_one_of(const char* setting, const char* values, std::string_view text) {
  return {setting, std::string("must be ") + values + ", not " + quoted(text)};
}

// A count or auto: its range is validate()'s, so any integer is read here.
std::optional<CountOrAuto> read_count(const char* setting, std::string_view text, bool allow_auto,
                                      std::vector<SettingProblem>* problems) {
  auto n = parse_count_or_auto(text, INT_MIN, INT_MAX, allow_auto);
  if (!n) {
    problems->push_back({setting, std::string("must be a whole number") +
                                      (allow_auto ? " or auto" : "") + ", not " + quoted(text)});
  }
  return n;
}

}  // namespace

std::optional<CountOrAuto> parse_count_or_auto(std::string_view text, int lo, int hi,
                                               bool allow_auto) {
  if (allow_auto && text == "auto") return CountOrAuto{0, true};
  int n = 0;
  const char* end = text.data() + text.size();
  // from_chars takes a minus sign; a plus sign, spaces or a fraction stop it short of the end.
  const auto [ptr, ec] = std::from_chars(text.data(), end, n);
  if (text.empty() || ec != std::errc() || ptr != end || n < lo || n > hi) return std::nullopt;
  return CountOrAuto{n, false};
}

std::optional<double> parse_number(std::string_view text) {
  double v = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, v);
  if (text.empty() || ec != std::errc() || ptr != end || !std::isfinite(v)) return std::nullopt;
  return v;
}

void set_counts(CountOrAuto slices, CountOrAuto components, FitSettings* settings) {
  if (slices.is_auto) {
    settings->auto_slices = true;
  } else {
    settings->auto_slices = false;  // a count replaces a data-chosen one
    settings->slices = slices.count;
    settings->slice_bounds.clear();
  }
  settings->auto_components = components.is_auto;
  settings->components = components.is_auto ? kAutoMaxComponents : components.count;
}

ParsedOptions parse_options(const EncoderOptions& o) {
  ParsedOptions parsed;
  EncoderSettings& st = parsed.settings;
  std::vector<SettingProblem>& problems = parsed.problems;
  const auto slices = read_count("slices", o.slices, true, &problems);
  if (o.placement == "adaptive") {
    st.fit.adaptive_slices = true;
  } else if (o.placement != "uniform") {
    problems.push_back(not_one_of("placement", "uniform or adaptive", o.placement));
  }
  if (o.family == "auto") {
    st.fit.auto_family = true;
  } else if (auto f = family_from_name(o.family)) {
    st.fit.family = *f;
  } else {
    problems.push_back(
        {"family", "must be " + family_list(", ") + " or auto, not " + quoted(o.family)});
  }
  const auto components = read_count("components", o.components, true, &problems);
  if (slices && components) set_counts(*slices, *components, &st.fit);
  if (o.mixture_copulas == "independence") {
    st.fit.mixture_copulas = false;
  } else if (o.mixture_copulas != "fit") {
    problems.push_back(not_one_of("mixture_copulas", "fit or independence", o.mixture_copulas));
  }
  if (o.loss == "linear") {
    st.fit.loss = FitLoss::kLinear;
  } else if (o.loss == "cosine") {
    st.fit.loss = FitLoss::kCosine;
  } else if (o.loss == "log") {
    st.fit.loss = FitLoss::kLog;
  } else {
    problems.push_back(not_one_of("loss", "linear, cosine or log", o.loss));
  }
  if (const auto bits = read_count("bits", o.bits, true, &problems)) {
    st.auto_bits.enabled = bits->is_auto;
    if (!bits->is_auto) st.container.bits = bits->count;
  }
  st.container.zstd_level = o.zstd_level;
  st.fit.threads = o.threads;
  const bool visibility = o.residual_steps == "visibility";
  if (o.residual_steps != "one" && !visibility) {
    problems.push_back(not_one_of("residual_steps", "one or visibility", o.residual_steps));
  }
  st.residual = residual_request(o.max_error, o.lossless, visibility);
  st.fit.impute_missing = !o.naive_marginals;
  st.container.source_name = o.source_name;
  if (o.format_version == "auto") {
    st.container.format = ContainerSettings::Format::kAuto;
  } else if (o.format_version == "1.2") {
    st.container.format = ContainerSettings::Format::kV12;
  } else if (o.format_version == "1.3") {
    st.container.format = ContainerSettings::Format::kV13;
  } else {
    problems.push_back(not_one_of("format_version", "auto, 1.2 or 1.3", o.format_version));
  }
  if (o.metadata == "none") {
    st.container.write_metadata = false;
  } else if (o.metadata == "short" || o.metadata == "full") {
    st.container.metadata = o.metadata == "short" ? ContainerSettings::Metadata::kShort
                                                  : ContainerSettings::Metadata::kFull;
  } else {
    problems.push_back(not_one_of("metadata", "none, short or full", o.metadata));
  }
  // A value that could not be read left its default, which validate() would not fault.
  for (SettingProblem& p : validate(st)) problems.push_back(std::move(p));
  // 0: one thread per core, resolved once the settings are known to be good.
  if (st.fit.threads == 0) st.fit.threads = thread_limit();
  return parsed;
}

Expected<EncoderSettings> encoder_settings(const EncoderOptions& options,
                                           const SettingSpelling& spell) {
  ParsedOptions parsed = parse_options(options);
  if (!parsed.problems.empty()) return settings_status(parsed.problems, spell);
  return std::move(parsed.settings);
}

ResidualSettings residual_request(double max_error, bool lossless, bool visibility_steps) {
  // Visibility steps: the layer rate control's PSNR targets write, bounded by max_error. Its
  // multipliers are derived from a bound in range only; steps without one stay visible to
  // validate(), which names residual_steps (or max_error).
  const bool bounded = max_error >= kMinResidualError && max_error <= kMaxResidualError;
  ResidualSettings rs =
      visibility_steps && bounded ? target_residual_settings(max_error) : ResidualSettings{};
  rs.max_error = max_error;
  rs.lossless = lossless;
  if (visibility_steps) rs.row_steps = true;
  return rs;
}

std::optional<SettingProblem> residual_option_conflict(const GivenResidualOptions& given) {
  // A bound or lossless beside a target would be dropped.
  if (given.target && (given.lossless || given.max_error)) {
    return SettingProblem{given.lossless ? "lossless" : "max_error",
                          "and a target ({target_bytes}, {target_psnr}) exclude each other: the "
                          "target chooses the residual layer itself; give one of them"};
  }
  if (given.residual_steps && given.target) {
    return SettingProblem{"residual_steps",
                          "and a target ({target_bytes}, {target_psnr}) exclude each other: a "
                          "target's residual layer always steps by visibility"};
  }
  return std::nullopt;
}

}  // namespace cbrdf
