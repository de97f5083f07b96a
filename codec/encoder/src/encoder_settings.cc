// SPDX-License-Identifier: MIT
// validate(): every range and combination check of EncoderSettings and RateTarget, named
// neutrally so that each front end words the same refusal in its own spelling.
#include "cbrdf/encoder_settings.h"

#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include "bitstream/chunks.h"
#include "cbrdf/container.h"
#include "cbrdf/copula_family.h"
#include "cbrdf/rate_control.h"

namespace cbrdf {
namespace {

static_assert(kMinResidualBound == kMinResidualError && kMaxResidualBound == kMaxResidualError,
              "the public bounds are the format's");

// The most fitting threads a caller may ask for (the C API documents it).
constexpr int kMaxFitThreads = 256;
// The highest target PSNR: far above any the model and residual reach, below absurd input.
constexpr double kMaxTargetPsnr = 1000.0;
// Container format and residual bounds are limits of the file; zstd's level range its own.
constexpr int kMinBits = 6;
constexpr int kMaxBits = 16;
constexpr int kMinZstdLevel = 1;
constexpr int kMaxZstdLevel = 22;

// "%g": 1e-06, 16, 0.02 (the bounds and PSNRs as users write them).
std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

// Byte counts in full: 67108864, not 6.71089e+07.
std::string byte_count(double v) {
  char text[40];
  std::snprintf(text, sizeof text, "%.15g", v);
  return text;
}

// "must be from LO to HI, not V"
std::string int_range(int lo, int hi, int value) {
  return "must be from " + std::to_string(lo) + " to " + std::to_string(hi) + ", not " +
         std::to_string(value);
}

void check_int(std::vector<SettingProblem>* out, const char* setting, int value, int lo, int hi) {
  if (value < lo || value > hi) out->push_back({setting, int_range(lo, hi, value)});
}

void check_fit(const FitSettings& fit, std::vector<SettingProblem>* out) {
  // A count is read only when it decides the slicing: explicit boundaries and auto override it.
  if (fit.slice_bounds.empty() && !fit.auto_slices) {
    check_int(out, "slices", fit.slices, 1, kThetaDBins);
  }
  if (!fit.slice_bounds.empty()) {
    const std::vector<int>& b = fit.slice_bounds;
    bool rising = b.size() >= 2 && b.front() == 0 && b.back() == kThetaDBins;
    for (std::size_t i = 1; rising && i < b.size(); ++i) rising = b[i] > b[i - 1];
    if (!rising) {
      out->push_back({"slice_bounds", "must rise strictly from 0 to " +
                                          std::to_string(kThetaDBins) + " (theta_d bins)"});
    }
  }
  if (!fit.auto_components) check_int(out, "components", fit.components, 1, kMaxComponents);
  if (!fit.auto_family && !family_valid(std::uint8_t(fit.family))) {
    out->push_back({"family", "must be one of " + family_list(", ") + ", not family id " +
                                  std::to_string(int(fit.family))});
  }
  if (fit.loss != FitLoss::kLinear && fit.loss != FitLoss::kCosine && fit.loss != FitLoss::kLog) {
    out->push_back(
        {"loss", "must be linear, cosine or log, not loss id " + std::to_string(int(fit.loss))});
  }
  if (fit.threads < 0 || fit.threads > kMaxFitThreads) {
    out->push_back({"threads", "must be from 0 (one per core) to " +
                                   std::to_string(kMaxFitThreads) + ", not " +
                                   std::to_string(fit.threads)});
  }
}

void check_container(const EncoderSettings& s, std::vector<SettingProblem>* out) {
  const ContainerSettings& c = s.container;
  if (!s.auto_bits.enabled) check_int(out, "bits", c.bits, kMinBits, kMaxBits);
  check_int(out, "zstd_level", c.zstd_level, kMinZstdLevel, kMaxZstdLevel);
  using Format = ContainerSettings::Format;
  if (c.format != Format::kAuto && c.format != Format::kV12 && c.format != Format::kV13) {
    out->push_back({"format_version",
                    "must be auto, 1.2 or 1.3, not format id " + std::to_string(int(c.format))});
  }
  using Metadata = ContainerSettings::Metadata;
  if (c.metadata != Metadata::kShort && c.metadata != Metadata::kFull) {
    out->push_back(
        {"metadata", "must be short or full, not metadata id " + std::to_string(int(c.metadata))});
  }
}

void check_residual(const ResidualSettings& r, std::vector<SettingProblem>* out) {
  // NaN fails both comparisons and is refused with the rest.
  if (r.max_error != 0 && !(r.max_error >= kMinResidualError && r.max_error <= kMaxResidualError)) {
    out->push_back({"max_error", "must be from " + number(kMinResidualError) + " to " +
                                     number(kMaxResidualError) + ", not " + number(r.max_error)});
  }
  if (r.lossless && r.max_error != 0) {
    out->push_back({"lossless", "and {max_error} exclude each other (lossless has no error)"});
  }
  if ((r.row_steps || r.levels > 0) && r.max_error == 0) {
    out->push_back({"residual_steps",
                    "visibility needs {max_error} above 0 (the bound of the most visible rows)"});
  }
  if (r.levels < 0 || r.levels > kMaxResidualLevels) {
    out->push_back({"residual_levels", int_range(0, kMaxResidualLevels, r.levels)});
  }
  if (r.levels > 0) {
    const auto multiplier = [&](const char* setting, int m, int lo) {
      check_int(out, setting, m, lo, kMaxFineMultiplier);
    };
    multiplier("fine_multiplier", r.fine_multiplier, 1);
    for (int m : r.middle_multipliers) multiplier("middle_multipliers", m, 1);
    multiplier("mode3_fine_multiplier", r.mode3_fine_multiplier, 0);
  }
}

}  // namespace

std::string cxx_spelling(std::string_view setting) {
  static constexpr std::pair<std::string_view, std::string_view> kMembers[] = {
      {"slices", "fit.slices"},
      {"slice_bounds", "fit.slice_bounds"},
      {"placement", "fit.adaptive_slices"},
      {"components", "fit.components"},
      {"family", "fit.family"},
      {"loss", "fit.loss"},
      {"threads", "fit.threads"},
      {"mixture_copulas", "fit.mixture_copulas"},
      {"bits", "container.bits"},
      {"zstd_level", "container.zstd_level"},
      {"format_version", "container.format"},
      {"metadata", "container.metadata"},
      {"max_error", "residual.max_error"},
      {"lossless", "residual.lossless"},
      {"residual_steps", "residual.row_steps"},
      {"residual_levels", "residual.levels"},
      {"fine_multiplier", "residual.fine_multiplier"},
      {"middle_multipliers", "residual.middle_multipliers"},
      {"mode3_fine_multiplier", "residual.mode3_fine_multiplier"},
      {"target_bytes", "RateTarget::max_bytes"},
      {"target_psnr", "RateTarget::min_psnr"},
      {"max_components", "RateTarget::max_components"},
      {"slice_counts", "RateTarget::slice_counts"},
  };
  for (const auto& [name, member] : kMembers) {
    if (name == setting) return std::string(member);
  }
  return std::string(setting);
}

std::vector<SettingProblem> validate(const EncoderSettings& settings) {
  std::vector<SettingProblem> out;
  check_fit(settings.fit, &out);
  check_container(settings, &out);
  check_residual(settings.residual, &out);
  return out;
}

std::vector<SettingProblem> validate(const RateTarget& target) {
  std::vector<SettingProblem> out;
  const double max_bytes = double(kMaxContainerBytes);
  if (target.max_bytes != 0 && !(target.max_bytes > 0 && target.max_bytes <= max_bytes)) {
    out.push_back({"target_bytes", "must be above 0 and at most " + byte_count(max_bytes) +
                                       " (64 MiB, the largest file), not " +
                                       byte_count(target.max_bytes)});
  }
  if (target.min_psnr != 0 && !(target.min_psnr > 0 && target.min_psnr <= kMaxTargetPsnr)) {
    out.push_back({"target_psnr", "must be above 0 and at most " + number(kMaxTargetPsnr) +
                                      " dB, not " + number(target.min_psnr)});
  }
  check_int(&out, "max_components", target.max_components, 1, kMaxComponents);
  if (target.slice_counts.empty()) {
    out.push_back({"slice_counts", "must list at least one slice count"});
  }
  for (int n : target.slice_counts) {
    if (n < 1 || n > kThetaDBins) {
      out.push_back({"slice_counts", "must hold counts from 1 to " + std::to_string(kThetaDBins) +
                                         ", not " + std::to_string(n)});
      break;
    }
  }
  return out;
}

std::string spell_problem(const SettingProblem& problem, const SettingSpelling& given) {
  const SettingSpelling spell =
      given ? given : [](std::string_view setting) { return std::string(setting); };
  std::string text = spell(problem.setting) + " ";
  const std::string& m = problem.message;
  for (std::size_t i = 0; i < m.size();) {
    const std::size_t close = m[i] == '{' ? m.find('}', i) : std::string::npos;
    if (close == std::string::npos) {
      text += m[i++];
      continue;
    }
    text += spell(std::string_view(m).substr(i + 1, close - i - 1));
    i = close + 1;
  }
  return text;
}

Status settings_status(std::span<const SettingProblem> problems, const SettingSpelling& spell) {
  if (problems.empty()) return ok_status();
  std::string text;
  for (const SettingProblem& p : problems) {
    if (!text.empty()) text += "; ";
    text += spell_problem(p, spell);
  }
  return error(ErrorCode::kInvalidArgument, text);
}

}  // namespace cbrdf
