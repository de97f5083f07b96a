// SPDX-License-Identifier: MIT
// Rendering time of a material in the figure-4 layout (render/builtin.h: six spheres under one
// directional light, every sphere in the measured material): the and the paper's Table 3
// comparison of rendering from the model against rendering from the measured table, at equal
// samples per pixel (one: delta light, exact).
#pragma once

#include <memory>

#include "cbrdf/brdf_table.h"
#include "cbrdf/model.h"
#include "render/material.h"

namespace cbrdf::report {

struct RenderTiming {
  int width = 0, height = 0;
  double seconds = 0;  // the faster of `repeats` renders on one thread
};

// Renders the layout at scale (1: 1320x240 pixels) with `material` on one thread, `repeats`
// times (at least once), and returns the fastest.
RenderTiming time_figure4_render(std::unique_ptr<render::Material> material, double scale,
                                 int repeats);

// The measured table's render times, nearest-bin and trilinear (render/table_lookup.h).
struct TableRenderTimes {
  double nearest_s = 0, trilinear_s = 0;
  int width = 0, height = 0;
};
TableRenderTimes time_table_renders(const BrdfTable& table, double scale, int repeats);

// A decoded model's render time.
double time_model_render(const Model& model, double scale, int repeats);

}  // namespace cbrdf::report
