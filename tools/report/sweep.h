// SPDX-License-Identifier: MIT
// `cbrdf report --sweep`: which codec settings to measure, and which baselines to run beside them.
#pragma once

#include <string>
#include <vector>

#include "cbrdf/encoder_options.h"
#include "cbrdf/status.h"

namespace cbrdf::report {

// CodecSetting::components for `--components auto` (FitSettings::auto_components, up to
// kAutoMaxComponents per slice and channel).
inline constexpr int kAutoComponents = 0;

// "1" to "8", or "auto" for kAutoComponents.
std::string components_name(int components);
// "6" to "16", or "auto" for kAutoBits (encoder.h).
std::string bits_name(int bits);

// "frank s6 b10", with " k2" (or " k-auto") appended for mixtures: K = 1 labels are the paper's
// model and read as they did before mixtures existed; " E0.03" for a residual layer.
std::string copula_label(const std::string& model_name, int slices, int bits, int components,
                         double max_error = 0);

// One codec setting: a point of the sweep.
struct CodecSetting {
  std::string family = "frank";  // frank, clayton, gumbel, joe, independence or auto
  int slices = 6;
  int bits = 10;
  int components = 1;  // 1 to kMaxComponents, or kAutoComponents
  // > 0: the model plus the residual layer whose bound E this is, stepped by visibility
  // (`cbrdf encode --max-error E --residual-steps visibility`, what rate control writes).
  double max_error = 0;
  bool operator==(const CodecSetting&) const = default;
  // "frank s6 b10", "frank s6 b10 k2", "frank s6 b10 E0.03"; the independence family is called
  // "separable", as in the paper.
  std::string label() const;
  std::string model_name() const;  // "frank", ..., "separable", "auto"
};

// The default setting of `cbrdf encode` (FitSettings and ContainerSettings defaults).
CodecSetting default_setting();

// The paper's setting, the reference every report measures: Frank, 6 uniform slices, one
// component, the default bits.
CodecSetting paper_setting();

struct Sweep {
  std::vector<std::string> families = {"frank"};
  std::vector<int> slices = {6};
  std::vector<int> bits = {10};
  std::vector<int> components = {1};  // kAutoComponents for auto
  // Residual bounds E: each adds the primary setting (at auto bits when `bits` holds auto) at each
  // component count plus the residual layer at E (none by default). Not a full product axis: a
  // layer costs seconds per setting and per coding, and over tens of KB it is the layer, not the
  // model's bits, that sets the picture.
  std::vector<double> residual;
  // The cartesian product: family, slices, components, bits (innermost), so that settings that
  // share a fit are adjacent; then the primary setting at each component count and residual bound.
  std::vector<CodecSetting> settings() const;
  // The setting the per-material images and the baseline comparison use: the default setting
  // when the sweep holds it, otherwise the first one.
  CodecSetting primary() const;
  // True when the paper's setting is the only one: every gain over it is 0 by construction.
  bool only_paper_setting() const;
};

// A sweep to suggest when there is nothing to compare with the paper's setting.
inline constexpr const char* kFrontierSweepExample = "--sweep components=1,2,4 bits=8,12";

// Parses items "slices=1,2,3", "bits=6,8", "family=frank,auto", "components=1,2,auto",
// "residual=0.1,0.03" (keys in any order, each at most once; an item may also hold several,
// separated by spaces). Errors
// (kInvalidArgument) are one line naming the item and what would be valid.
Expected<Sweep> parse_sweep(const std::vector<std::string>& items);

// Baselines measured beside the sweep.
struct Baselines {
  bool lossless = false;  // zstd -19 and xz -6 of the .binary bytes (about 25 s per material)
  bool float16 = true;    // physical values as IEEE half, then zstd
  bool separable = true;  // the independence copula at the primary setting
  bool families = false;  // every copula family and auto at the primary setting
  bool analytic = true;   // Ward, Cook-Torrance (GGX), Ashikhmin-Shirley, two-lobe GGX
};
inline constexpr const char* kBaselineNames = "lossless, float16, separable, families, analytic";

// "all", "none", or a comma-separated list of the names above.
Expected<Baselines> parse_baselines(const std::string& list);

}  // namespace cbrdf::report
