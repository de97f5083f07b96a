// SPDX-License-Identifier: MIT
#include "render/material.h"

#include <algorithm>
#include <chrono>
#include <random>

#include "cbrdf/codec.h"
#include "cbrdf/container.h"
#include "cbrdf/file_io.h"
#include "cbrdf/merl_io.h"
#include "cbrdf/samples.h"
#include "render/table_lookup.h"

namespace cbrdf::render {

std::string Material::use_table(BrdfTable table, bool trilinear) {
  table_ = std::make_unique<BrdfTable>(std::move(table));
  const BrdfTable* t = table_.get();
  if (trilinear) {
    fn_ = [t](const Vec3& wi, const Vec3& wo, double rgb[3]) {
      lookup_trilinear_measured(*t, wi, wo, rgb);
    };
  } else {
    fn_ = nearest_lookup_fn(*t);
  }
  return std::string(trilinear ? "trilinear" : "nearest-bin") + " lookup";
}

void Material::use_model(Model model) {
  model_ = std::make_unique<Model>(std::move(model));
  evaluator_ = std::make_unique<ModelEvaluator>(*model_);
  fn_ = model_brdf_fn(*evaluator_);
}

void Material::finish() {
  if (!fn_) {
    const AnalyticBrdf* a = &analytic_;
    fn_ = [a](const Vec3& wi, const Vec3& wo, double rgb[3]) { a->eval(wi, wo, rgb); };
  }
  sampler_ = std::make_unique<BrdfSampler>(fn_);
}

std::unique_ptr<Material> Material::from_table(std::string name, BrdfTable table, bool trilinear) {
  std::unique_ptr<Material> m(new Material());
  m->name_ = std::move(name);
  m->description_ = "measured table, " + m->use_table(std::move(table), trilinear);
  m->finish();
  return m;
}

std::unique_ptr<Material> Material::from_model(std::string name, Model model) {
  std::unique_ptr<Material> m(new Material());
  m->name_ = std::move(name);
  m->use_model(std::move(model));
  m->description_ = "copula model, " + std::to_string(m->model_->slices.size()) + " slices";
  m->finish();
  return m;
}

Expected<std::unique_ptr<Material>> Material::create(const MaterialDesc& desc) {
  std::unique_ptr<Material> m(new Material());
  m->name_ = desc.name;
  const std::string file = desc.file.filename().string();
  const auto use_table = [&m, &desc](BrdfTable table) {
    return m->use_table(std::move(table), desc.linear_lookup);
  };
  switch (desc.type) {
    case MaterialType::kMerl: {
      CBRDF_ASSIGN_OR_RETURN(auto table, read_merl(desc.file));
      m->description_ = "measured table, " + use_table(std::move(table)) + " (" + file + ")";
      break;
    }
    case MaterialType::kCbrdf: {
      CBRDF_ASSIGN_OR_RETURN(auto bytes, read_file(desc.file, kMaxContainerBytes));
      auto model = decode_model(bytes);
      if (!model.ok()) return model.status().with_context(desc.file.string());
      m->use_model(std::move(*model));
      m->description_ =
          "copula model, " + std::to_string(m->model_->slices.size()) + " slices (" + file + ")";
      break;
    }
    case MaterialType::kSample: {
      const auto all = sample_materials();
      if (std::any_of(all.begin(), all.end(), [&desc](const SampleInfo& s) {
            return s.name == desc.sample_name && s.kind == SampleKind::kMeasured;
          })) {
        // No analytic form: the sample's MERL table, looked up as a "merl" material would be.
        auto table = make_sample(desc.sample_name);
        if (!table.ok()) return table.status().with_context("material '" + desc.name + "'");
        m->description_ =
            "measured sample '" + desc.sample_name + "', " + use_table(std::move(*table));
        break;
      }
      auto brdf = sample_brdf(desc.sample_name);
      if (!brdf.ok()) return brdf.status().with_context("material '" + desc.name + "'");
      m->analytic_ = std::move(*brdf);
      m->description_ = "analytic sample '" + desc.sample_name + "'";
      break;
    }
    case MaterialType::kAnalytic:
      m->analytic_ = AnalyticBrdf{desc.lobes};
      m->description_ = "analytic, " + std::to_string(desc.lobes.size()) + " lobe(s)";
      break;
  }
  m->finish();
  return m;
}

double eval_cost_ns(const Material& m, int pairs) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vec3> dirs(std::size_t(2 * pairs));
  for (Vec3& d : dirs) d = sample_cosine_hemisphere(u(rng), u(rng));
  double sink = 0;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < pairs; ++i) {
    double rgb[3];
    m.eval(dirs[std::size_t(2 * i)], dirs[std::size_t(2 * i + 1)], rgb);
    sink += rgb[0] + rgb[1] + rgb[2];
  }
  const double ns =
      std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count();
  // Keeps the loop from being optimized away.
  if (sink == -1.0) return 0.0;
  return ns / std::max(1, pairs);
}

}  // namespace cbrdf::render
