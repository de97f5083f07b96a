// SPDX-License-Identifier: MIT
// Render materials: every BRDF source behind one interface, local frame (z = normal), physical RGB.
#pragma once

#include <memory>
#include <string>

#include "cbrdf/analytic.h"
#include "cbrdf/brdf_table.h"
#include "cbrdf/metrics.h"
#include "cbrdf/model.h"
#include "cbrdf/sampling.h"
#include "cbrdf/status.h"
#include "render/scene.h"

namespace cbrdf::render {

class Material {
 public:
  // Loads the material's data (MERL table, .cbrdf model, analytic lobes). Errors name the file.
  static Expected<std::unique_ptr<Material>> create(const MaterialDesc& desc);
  // In-memory sources (the report times renders with them): a measured table looked up at the
  // nearest bin or trilinearly (render/table_lookup.h), or a decoded model.
  static std::unique_ptr<Material> from_table(std::string name, BrdfTable table, bool trilinear);
  static std::unique_ptr<Material> from_model(std::string name, Model model);

  void eval(const Vec3& wi, const Vec3& wo, double rgb[3]) const { fn_(wi, wo, rgb); }
  // Importance sampling of this BRDF (cbrdf/sampling.h); its tables are built on first use.
  const BrdfSampler& sampler() const { return *sampler_; }
  const std::string& name() const { return name_; }
  // "cbrdf model (plastic.cbrdf)", for the render log.
  const std::string& description() const { return description_; }

 private:
  Material() = default;
  // Sets fn_ (and the description's lookup part) for table_.
  std::string use_table(BrdfTable table, bool trilinear);
  void use_model(Model model);
  void finish();  // the analytic fallback for fn_ and the sampler
  std::string name_, description_;
  std::unique_ptr<BrdfTable> table_;
  std::unique_ptr<Model> model_;
  std::unique_ptr<ModelEvaluator> evaluator_;
  AnalyticBrdf analytic_;
  BrdfFn fn_;
  std::unique_ptr<BrdfSampler> sampler_;
};

// Mean cost of one eval() in nanoseconds over `pairs` random direction pairs above the horizon
// (one thread), for the render log's model-versus-table comparison.
double eval_cost_ns(const Material& m, int pairs);

}  // namespace cbrdf::render
