// SPDX-License-Identifier: MIT
#include "report/render_times.h"

#include <algorithm>
#include <chrono>
#include <limits>
#include <memory>
#include <utility>
#include <vector>

#include "render/builtin.h"
#include "render/integrator.h"

namespace cbrdf::report {

RenderTiming time_figure4_render(std::unique_ptr<render::Material> material, double scale,
                                 int repeats) {
  render::MaterialDesc desc;
  desc.name = material->name();
  const render::Scene scene = render::figure4_one_material(desc, scale);
  std::vector<std::unique_ptr<render::Material>> materials;
  materials.push_back(std::move(material));
  const render::RenderPlan plan = render::plan_render(scene, 1);
  RenderTiming t{scene.width, scene.height, std::numeric_limits<double>::infinity()};
  for (int i = 0; i < std::max(1, repeats); ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    const Image img = render::render(scene, materials, plan, 1);
    t.seconds = std::min(
        t.seconds, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return t;
}

TableRenderTimes time_table_renders(const BrdfTable& table, double scale, int repeats) {
  TableRenderTimes out;
  const RenderTiming n = time_figure4_render(
      render::Material::from_table("table-nearest", table, false), scale, repeats);
  out.nearest_s = n.seconds;
  out.width = n.width;
  out.height = n.height;
  out.trilinear_s =
      time_figure4_render(render::Material::from_table("table-trilinear", table, true), scale,
                          repeats)
          .seconds;
  return out;
}

double time_model_render(const Model& model, double scale, int repeats) {
  return time_figure4_render(render::Material::from_model("model", model), scale, repeats).seconds;
}

}  // namespace cbrdf::report
