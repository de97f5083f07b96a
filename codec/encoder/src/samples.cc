// SPDX-License-Identifier: MIT
#include "cbrdf/samples.h"

#include <algorithm>
#include <array>
#include <string>

#include "embedded_files.h"
#include "nbrdf.h"

namespace cbrdf {
namespace {

constexpr std::string_view kMerlSource =
    "MERL BRDF database (Matusik et al. 2003), neural fit by Sztrajman et al. 2021 (MIT licence)";

// The measured samples (data/measured/NAME.nbrdf, compiled in): the copula paper's three
// materials, then a fabric, a metal, a plastic and a paint.
const std::array<SampleInfo, 7> kMeasured = {{
    {"blue-metallic-paint", "MERL blue metallic car paint (the copula paper's Table 1)",
     SampleKind::kMeasured, kMerlSource},
    {"nickel", "MERL nickel, a bright grey metal (the copula paper's Table 1)",
     SampleKind::kMeasured, kMerlSource},
    {"yellow-matte-plastic", "MERL yellow matte plastic (the copula paper's Table 1)",
     SampleKind::kMeasured, kMerlSource},
    {"pink-felt", "MERL pink felt, a fabric", SampleKind::kMeasured, kMerlSource},
    {"alum-bronze", "MERL aluminium bronze, a coloured metal", SampleKind::kMeasured, kMerlSource},
    {"red-specular-plastic", "MERL red plastic with a white highlight", SampleKind::kMeasured,
     kMerlSource},
    {"gold-metallic-paint", "MERL gold metallic car paint", SampleKind::kMeasured, kMerlSource},
}};

struct SampleDef {
  SampleInfo info;
  std::vector<Lobe> (*lobes)();
};

// Colours differ per channel so that a channel mix-up anywhere downstream shows.
const std::array<SampleDef, 7> kSamples = {{
    {{"lambertian", "matte orange: Lambertian, albedo (0.80, 0.45, 0.15)"},
     [] {
       return std::vector<Lobe>{lambertian({0.80, 0.45, 0.15})};
     }},
    {{"ggx-rough", "rough copper: GGX alpha 0.5, F0 (0.95, 0.64, 0.54)"},
     [] {
       return std::vector<Lobe>{ggx({0.95, 0.64, 0.54}, 0.5)};
     }},
    {{"ggx-sharp", "polished gold: GGX alpha 0.08, F0 (1.00, 0.71, 0.29)"},
     [] {
       return std::vector<Lobe>{ggx({1.00, 0.71, 0.29}, 0.08)};
     }},
    {{"ward",
      "blue enamel: Lambertian (0.05, 0.10, 0.30) + Ward alpha 0.2, rho_s (0.20, 0.25, 0.35)"},
     [] {
       return std::vector<Lobe>{lambertian({0.05, 0.10, 0.30}), ward({0.20, 0.25, 0.35}, 0.2)};
     }},
    {{"plastic", "red plastic: Lambertian (0.55, 0.08, 0.06) + GGX alpha 0.12, F0 0.04"},
     [] {
       return std::vector<Lobe>{lambertian({0.55, 0.08, 0.06}), ggx({0.04, 0.04, 0.04}, 0.12)};
     }},
    {{"near-mirror",
      "silver mirror: GGX alpha 0.015, F0 (0.97, 0.95, 0.90); the copula's hardest case"},
     [] {
       return std::vector<Lobe>{ggx({0.97, 0.95, 0.90}, 0.015)};
     }},
    {{"ashikhmin-shirley",
      "green lacquer: Lambertian (0.10, 0.35, 0.12) + Ashikhmin-Shirley n 300, Rs 0.05"},
     [] {
       return std::vector<Lobe>{lambertian({0.10, 0.35, 0.12}),
                                ashikhmin_shirley({0.05, 0.05, 0.05}, 300.0)};
     }},
}};

const std::array<SampleInfo, kMeasured.size() + kSamples.size()> kInfos = [] {
  std::array<SampleInfo, kMeasured.size() + kSamples.size()> infos{};
  std::copy(kMeasured.begin(), kMeasured.end(), infos.begin());
  for (std::size_t i = 0; i < kSamples.size(); ++i) infos[kMeasured.size() + i] = kSamples[i].info;
  return infos;
}();

std::string valid_names() {
  std::string names;
  for (const SampleInfo& info : kInfos) {
    if (!names.empty()) names += ", ";
    names += info.name;
  }
  return names;
}

bool is_measured(std::string_view name) {
  return std::any_of(kMeasured.begin(), kMeasured.end(),
                     [name](const SampleInfo& info) { return info.name == name; });
}

Status unknown_sample(std::string_view name) {
  return error(ErrorCode::kInvalidArgument, "unknown sample material '" + std::string(name) +
                                                "'; valid names: " + valid_names());
}

Expected<BrdfTable> make_measured(std::string_view name) {
  for (const internal::EmbeddedFile& f : internal::embedded_nbrdf_files()) {
    if (f.name != name) continue;
    Expected<internal::NbrdfNet> net = internal::parse_nbrdf(f.bytes, name);
    if (!net) return net.status();
    return internal::tabulate_nbrdf(*net);
  }
  return error(ErrorCode::kInternal, "measured sample '" + std::string(name) +
                                         "' has no embedded weights (data/measured/" +
                                         std::string(name) + ".nbrdf was not compiled in)");
}

}  // namespace

std::span<const SampleInfo> sample_materials() {
  return kInfos;
}

Expected<AnalyticBrdf> sample_brdf(std::string_view name) {
  for (const SampleDef& def : kSamples) {
    if (def.info.name == name) return AnalyticBrdf{def.lobes()};
  }
  if (is_measured(name)) {
    return error(ErrorCode::kInvalidArgument,
                 std::string(name) +
                     " is a measured sample (neural fit of MERL data); it has no analytic form");
  }
  return unknown_sample(name);
}

Expected<BrdfTable> make_sample(std::string_view name) {
  const auto named = [name](Expected<BrdfTable> table) -> Expected<BrdfTable> {
    if (!table) return table.status().with_context("sample '" + std::string(name) + "'");
    return table;
  };
  if (is_measured(name)) return named(make_measured(name));
  Expected<AnalyticBrdf> brdf = sample_brdf(name);
  if (!brdf) return brdf.status();  // an unknown name: the message lists the valid ones
  return named(tabulate(*brdf));
}

}  // namespace cbrdf
