// SPDX-License-Identifier: MIT
#include "cbrdf/samples.h"

#include <array>
#include <string>

namespace cbrdf {
namespace {

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

const std::array<SampleInfo, kSamples.size()> kInfos = [] {
  std::array<SampleInfo, kSamples.size()> infos{};
  for (std::size_t i = 0; i < kSamples.size(); ++i) infos[i] = kSamples[i].info;
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

}  // namespace

std::span<const SampleInfo> sample_materials() {
  return kInfos;
}

Expected<AnalyticBrdf> sample_brdf(std::string_view name) {
  for (const SampleDef& def : kSamples) {
    if (def.info.name == name) return AnalyticBrdf{def.lobes()};
  }
  return error(ErrorCode::kInvalidArgument, "unknown sample material '" + std::string(name) +
                                                "'; valid names: " + valid_names());
}

Expected<BrdfTable> make_sample(std::string_view name) {
  Expected<AnalyticBrdf> brdf = sample_brdf(name);
  if (!brdf) return brdf.status();
  Expected<BrdfTable> table = tabulate(*brdf);
  if (!table) return table.status().with_context("sample '" + std::string(name) + "'");
  return table;
}

}  // namespace cbrdf
