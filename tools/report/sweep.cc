// SPDX-License-Identifier: MIT
// Included by name relative to this folder (not "report/..."): tests compile this file alone.
#include "report/sweep.h"

#include <algorithm>
#include <charconv>
#include <climits>
#include <cstdio>
#include <optional>
#include <sstream>
#include <system_error>

#include "cbrdf/codec.h"
#include "cbrdf/copula_family.h"
#include "cbrdf/encoder.h"
#include "cbrdf/encoder_options.h"
#include "cbrdf/encoder_settings.h"
#include "cbrdf/fit.h"

namespace cbrdf::report {
namespace {

Status bad(const std::string& message) {
  return error(ErrorCode::kInvalidArgument, "--sweep: " + message);
}

std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> parts;
  std::string part;
  std::istringstream in(text);
  while (std::getline(in, part, sep)) parts.push_back(part);
  if (!text.empty() && text.back() == sep) parts.emplace_back();
  return parts;
}

// The report's spelling of a neutral setting name: its --sweep key.
std::string sweep_spelling(std::string_view setting) {
  return setting == "max_error" ? "residual" : std::string(setting);
}

// The encoder's refusal (validate()) of one swept value, set on default settings by `apply`.
template <typename Apply>
Status check_value(const char* setting, Apply apply) {
  EncoderSettings probe;
  apply(&probe);
  std::vector<SettingProblem> problems;
  for (SettingProblem& p : validate(probe)) {
    if (p.setting == setting) problems.push_back(std::move(p));
  }
  if (problems.empty()) return ok_status();
  return bad(settings_status(problems, sweep_spelling).message());
}

// A list of "integer or auto" values (auto only when allow_auto; it stands as kAutoComponents),
// each within the range validate() holds `setting` to.
Expected<std::vector<int>> parse_counts(const std::string& key, const std::string& values,
                                        const char* setting, bool allow_auto) {
  std::vector<int> out;
  for (const std::string& v : split(values, ',')) {
    const std::optional<CountOrAuto> n = parse_count_or_auto(v, INT_MIN, INT_MAX, allow_auto);
    if (!n) {
      return bad(key + "='" + v + "' is not a whole number" + (allow_auto ? " or auto" : ""));
    }
    if (!n->is_auto) {
      const std::string name = setting;
      CBRDF_RETURN_IF_ERROR(check_value(setting, [&](EncoderSettings* probe) {
        if (name == "slices") probe->fit.slices = n->count;
        if (name == "components") probe->fit.components = n->count;
        if (name == "bits") {
          probe->auto_bits.enabled = false;
          probe->container.bits = n->count;
        }
      }));
    }
    const int x = n->is_auto ? kAutoComponents : n->count;
    if (std::find(out.begin(), out.end(), x) != out.end()) {
      return bad(key + " lists " + v + " twice");
    }
    out.push_back(x);
  }
  return out;
}

// Residual bounds, as --max-error takes them; 0 (no layer) is no entry of this list.
Expected<std::vector<double>> parse_bounds(const std::string& values) {
  std::vector<double> out;
  for (const std::string& v : split(values, ',')) {
    const std::optional<double> x = parse_number(v);
    if (!x) return bad("residual='" + v + "' is not a number");
    if (*x == 0) return bad("residual=0 adds no layer; list bounds above 0");
    CBRDF_RETURN_IF_ERROR(
        check_value("max_error", [&](EncoderSettings* probe) { probe->residual.max_error = *x; }));
    if (std::find(out.begin(), out.end(), *x) != out.end()) {
      return bad("residual lists " + v + " twice");
    }
    out.push_back(*x);
  }
  return out;
}

Expected<std::vector<std::string>> parse_families(const std::string& values) {
  std::vector<std::string> out;
  for (std::string v : split(values, ',')) {
    if (v == "separable") v = "independence";
    if (v != "auto" && !family_from_name(v)) {
      return bad("family='" + v + "' is not one of " + family_list(", ") + " (or separable), auto");
    }
    if (std::find(out.begin(), out.end(), v) != out.end()) {
      return bad("family lists " + v + " twice");
    }
    out.push_back(v);
  }
  return out;
}

// The default setting when the models measured hold it, otherwise the first of them.
CodecSetting primary_of(const std::vector<CodecSetting>& models) {
  const CodecSetting def = default_setting();
  if (std::find(models.begin(), models.end(), def) != models.end()) return def;
  return models.front();
}

}  // namespace

std::string components_name(int components) {
  return components == kAutoComponents ? "auto" : std::to_string(components);
}

std::string bits_name(int bits) {
  return bits == kAutoBits ? "auto" : std::to_string(bits);
}

std::string copula_label(const std::string& model_name, int slices, int bits, int components,
                         double max_error) {
  std::string label = model_name + " s" + std::to_string(slices) + " b" + bits_name(bits);
  if (components == kAutoComponents) label += " k-auto";
  if (components != 1 && components != kAutoComponents) label += " k" + std::to_string(components);
  if (max_error > 0) {
    char text[32];
    std::snprintf(text, sizeof text, " E%g", max_error);
    label += text;
  }
  return label;
}

std::string CodecSetting::model_name() const {
  return family == "independence" ? "separable" : family;
}

std::string CodecSetting::label() const {
  return copula_label(model_name(), slices, bits, components, max_error);
}

CodecSetting default_setting() {
  const FitSettings fit;
  CodecSetting s;
  s.family = fit.auto_family ? "auto" : std::string(family_name(fit.family));
  s.slices = fit.slices;
  s.bits = ContainerSettings{}.bits;
  s.components = fit.auto_components ? kAutoComponents : fit.components;
  return s;
}

CodecSetting paper_setting() {
  return CodecSetting{"frank", 6, ContainerSettings{}.bits, 1};
}

bool Sweep::only_paper_setting() const {
  const std::vector<CodecSetting> all = settings();
  return all.size() == 1 && all.front() == paper_setting();
}

std::vector<CodecSetting> Sweep::settings() const {
  std::vector<CodecSetting> out;
  for (const std::string& f : families) {
    for (int s : slices) {
      for (int k : components) {
        for (int b : bits) out.push_back(CodecSetting{f, s, b, k});
      }
    }
  }
  // The layer on the primary setting at each component count: at coarse bounds a mixture carries
  // shape the layer would pay for, at fine ones one component under it costs less (docs). With
  // bits=auto in the sweep it sits on the bits the command chooses, as `cbrdf encode --max-error E`
  // without --bits does: the layer corrects what coarser marginals miss, and on the 20 real
  // materials the model under it is 0.9 to 1.4 KB smaller than at 12 bits for 0.01 dB.
  const CodecSetting primary = primary_of(out);
  const bool auto_bits = std::find(bits.begin(), bits.end(), kAutoBits) != bits.end();
  for (int k : components) {
    for (double e : residual) {
      CodecSetting base = primary;
      if (auto_bits) base.bits = kAutoBits;
      base.components = k;
      base.max_error = e;
      out.push_back(base);
    }
  }
  return out;
}

CodecSetting Sweep::primary() const {
  return primary_of(settings());
}

Expected<Sweep> parse_sweep(const std::vector<std::string>& items) {
  Sweep sweep;
  sweep.families = {default_setting().family};
  sweep.slices = {default_setting().slices};
  sweep.bits = {default_setting().bits};
  sweep.components = {default_setting().components};
  std::vector<std::string> seen;
  for (const std::string& item : items) {
    std::istringstream words(item);
    std::string word;
    while (words >> word) {
      const std::size_t eq = word.find('=');
      if (eq == std::string::npos || eq == 0) {
        return bad("'" + word +
                   "' is not KEY=VALUES (keys: slices, bits, family, components, residual; give "
                   "input files before --sweep)");
      }
      const std::string key = word.substr(0, eq), values = word.substr(eq + 1);
      if (std::find(seen.begin(), seen.end(), key) != seen.end()) {
        return bad("'" + key + "' is given twice; list all its values once, e.g. " + key + "=A,B");
      }
      if (values.empty()) return bad("'" + key + "=' has no values");
      seen.push_back(key);
      if (key == "slices") {
        auto v = parse_counts(key, values, "slices", false);
        if (!v) return v.status();
        sweep.slices = *v;
      } else if (key == "bits") {
        auto v = parse_counts(key, values, "bits", true);  // auto: kAutoBits
        if (!v) return v.status();
        sweep.bits = *v;
      } else if (key == "family" || key == "families") {
        auto v = parse_families(values);
        if (!v) return v.status();
        sweep.families = *v;
      } else if (key == "components") {
        auto v = parse_counts(key, values, "components", true);
        if (!v) return v.status();
        sweep.components = *v;
      } else if (key == "residual") {
        auto v = parse_bounds(values);
        if (!v) return v.status();
        sweep.residual = *v;
      } else {
        return bad("unknown key '" + key + "' (keys: slices, bits, family, components, residual)");
      }
    }
  }
  return sweep;
}

Expected<Baselines> parse_baselines(const std::string& list) {
  Baselines b;
  if (list == "all") return Baselines{true, true, true, true, true};
  b = Baselines{false, false, false, false, false};
  if (list == "none") return b;
  for (const std::string& name : split(list, ',')) {
    if (name == "lossless") {
      b.lossless = true;
    } else if (name == "float16") {
      b.float16 = true;
    } else if (name == "separable") {
      b.separable = true;
    } else if (name == "families") {
      b.families = true;
    } else if (name == "analytic") {
      b.analytic = true;
    } else {
      return error(ErrorCode::kInvalidArgument, "--baselines: unknown baseline '" + name +
                                                    "' (all, none, or a list of " + kBaselineNames +
                                                    ")");
    }
  }
  return b;
}

}  // namespace cbrdf::report
