// SPDX-License-Identifier: MIT
// The user-facing encoder options (`cbrdf encode`, `cbrdf report`, rate control) as
// EncoderSettings: one place for their parsing, their defaults and their error messages.
#include "encoder_options.h"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <thread>

#include "cbrdf/encoder.h"
#include "cbrdf/parallel.h"

namespace cbrdf {
namespace {

Status invalid(const std::string& message) {
  return error(ErrorCode::kInvalidArgument, message);
}

}  // namespace

std::optional<CountOrAuto> parse_count_or_auto(std::string_view text, int lo, int hi,
                                               bool allow_auto) {
  if (allow_auto && text == "auto") return CountOrAuto{0, true};
  int n = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, n);
  if (text.empty() || ec != std::errc() || ptr != end || n < lo || n > hi) return std::nullopt;
  return CountOrAuto{n, false};
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

// Checked in the order `cbrdf encode` always has: the first bad option is the one named.
Expected<EncoderSettings> encoder_settings(const EncoderOptions& o) {
  EncoderSettings st;
  const auto slices = parse_count_or_auto(o.slices, 1, kThetaDBins, true);
  if (!slices) return invalid("--slices must be 1 to 90 or auto, not '" + o.slices + "'");
  if (o.placement == "adaptive") {
    st.fit.adaptive_slices = true;
  } else if (o.placement != "uniform") {
    return invalid("unknown --slice-placement '" + o.placement + "' (uniform or adaptive)");
  }
  if (o.family == "auto") {
    st.fit.auto_family = true;
  } else if (auto f = family_from_name(o.family)) {
    st.fit.family = *f;
  } else {
    return invalid("unknown --family '" + o.family + "' (" + family_list(", ") + " or auto)");
  }
  const auto components = parse_count_or_auto(o.components, 1, kMaxComponents, true);
  if (!components) {
    return invalid("--components must be 1 to " + std::to_string(kMaxComponents) +
                   " or auto, not '" + o.components + "'");
  }
  set_counts(*slices, *components, &st.fit);
  if (o.mixture_copulas == "independence") {
    st.fit.mixture_copulas = false;
  } else if (o.mixture_copulas != "fit") {
    return invalid("unknown --mixture-copulas '" + o.mixture_copulas + "' (fit or independence)");
  }
  if (o.loss == "linear") {
    st.fit.loss = FitLoss::kLinear;
  } else if (o.loss == "cosine") {
    st.fit.loss = FitLoss::kCosine;
  } else if (o.loss == "log") {
    st.fit.loss = FitLoss::kLog;
  } else {
    return invalid("unknown --loss '" + o.loss + "' (linear, cosine or log)");
  }
  if (o.bits != kAutoBits && (o.bits < 6 || o.bits > 16)) {
    return invalid("--bits must be 6 to 16 or auto, not " + std::to_string(o.bits));
  }
  if (o.level < 1 || o.level > 22) {
    return invalid("--level must be 1 to 22, not " + std::to_string(o.level));
  }
  if (o.threads < 0) {
    return invalid("--threads must be 0 (one per core) or more, not " + std::to_string(o.threads));
  }
  if (o.lossless && o.max_error != 0) {
    return invalid("--max-error and --lossless exclude each other (lossless has no error)");
  }
  if (o.max_error != 0 && !(o.max_error >= 1e-6 && o.max_error <= 16)) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", o.max_error);
    return invalid(std::string("--max-error must be 1e-06 to 16 (or 0: no residual layer), not ") +
                   text);
  }
  if (o.residual_steps != "one" && o.residual_steps != "visibility") {
    return invalid("--residual-steps must be one or visibility, not '" + o.residual_steps + "'");
  }
  const bool visibility = o.residual_steps == "visibility";
  if (visibility && o.max_error == 0) {
    return invalid(
        "--residual-steps visibility needs --max-error E (the bound of the most visible rows)");
  }
  st.residual = residual_request(o.max_error, o.lossless, visibility);
  st.fit.impute_missing = !o.naive_marginals;
  st.fit.threads = o.threads > 0 ? o.threads : thread_limit();
  st.auto_bits.enabled = o.bits == kAutoBits;
  if (!st.auto_bits.enabled) st.container.bits = o.bits;
  st.container.zstd_level = o.level;
  st.container.source_name = o.source_name;
  if (o.format_version == "auto") {
    st.container.format = ContainerSettings::Format::kAuto;
  } else if (o.format_version == "1.2") {
    st.container.format = ContainerSettings::Format::kV12;
  } else if (o.format_version == "1.3") {
    st.container.format = ContainerSettings::Format::kV13;
  } else {
    return invalid("--format-version must be auto, 1.2 or 1.3, not '" + o.format_version + "'");
  }
  if (o.metadata == "none") {
    st.container.write_metadata = false;
  } else if (o.metadata == "short" || o.metadata == "full") {
    st.container.metadata = o.metadata == "short" ? ContainerSettings::Metadata::kShort
                                                  : ContainerSettings::Metadata::kFull;
  } else {
    return invalid("--metadata must be none, short or full, not '" + o.metadata + "'");
  }
  return st;
}

ResidualSettings residual_request(double max_error, bool lossless, bool visibility_steps) {
  // Visibility steps: the layer rate control's PSNR targets write, bounded by max_error.
  ResidualSettings rs = visibility_steps ? target_residual_settings(max_error) : ResidualSettings{};
  rs.max_error = max_error;
  rs.lossless = lossless;
  return rs;
}

std::optional<std::string> residual_option_conflict(const GivenResidualOptions& given) {
  // A bound or lossless beside a target would be dropped.
  if (given.target && (given.lossless || given.max_error)) {
    return std::string(given.lossless ? "--lossless" : "--max-error") +
           " and a target (--target-bytes, --target-psnr) exclude each other: the target "
           "chooses the residual layer itself; give one of them";
  }
  if (given.residual_steps && given.target) {
    return std::string(
        "--residual-steps and a target (--target-bytes, --target-psnr) exclude each other: a "
        "target's residual layer always steps by visibility");
  }
  if (given.residual_steps && !given.max_error) {
    return std::string(
        "--residual-steps shapes the layer --max-error E adds; give --max-error too");
  }
  return std::nullopt;
}

EncoderSettings command_defaults() {
  // The default options are valid by construction (encoder_options_test).
  return encoder_settings(EncoderOptions{}).value();
}

}  // namespace cbrdf
