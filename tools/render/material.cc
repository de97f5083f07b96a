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

namespace cbrdf::render {

Expected<std::unique_ptr<Material>> Material::create(const MaterialDesc& desc) {
  std::unique_ptr<Material> m(new Material());
  m->name_ = desc.name;
  const std::string file = desc.file.filename().string();
  const auto use_table = [&m, &desc](BrdfTable table) {
    m->table_ = std::make_unique<BrdfTable>(std::move(table));
    const BrdfTable* t = m->table_.get();
    if (desc.linear_lookup) {
      m->fn_ = [t](const Vec3& wi, const Vec3& wo, double rgb[3]) {
        lookup_linear(*t, wi, wo, rgb);
      };
    } else {
      m->fn_ = nearest_lookup_fn(*t);
    }
    return std::string(desc.linear_lookup ? "trilinear" : "nearest-bin") + " lookup";
  };
  switch (desc.type) {
    case MaterialType::kMerl: {
      auto table = read_merl(desc.file);
      if (!table.ok()) return table.status();
      m->description_ = "measured table, " + use_table(std::move(*table)) + " (" + file + ")";
      break;
    }
    case MaterialType::kCbrdf: {
      auto bytes = read_file(desc.file, kMaxContainerBytes);
      if (!bytes.ok()) return bytes.status();
      auto model = decode_model(*bytes);
      if (!model.ok()) return model.status().with_context(desc.file.string());
      m->model_ = std::make_unique<Model>(std::move(*model));
      m->evaluator_ = std::make_unique<ModelEvaluator>(*m->model_);
      m->fn_ = model_brdf_fn(*m->evaluator_);
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
  if (!m->fn_) {
    const AnalyticBrdf* a = &m->analytic_;
    m->fn_ = [a](const Vec3& wi, const Vec3& wo, double rgb[3]) { a->eval(wi, wo, rgb); };
  }
  m->sampler_ = std::make_unique<BrdfSampler>(m->fn_);
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
