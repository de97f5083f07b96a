// SPDX-License-Identifier: MIT
// The renderer's integrators, chosen from what the scene contains (plan_render), and the render.
//
// Delta lights only (point, directional) and no indirect bounces: one ray through each pixel
// centre and one shadow ray per light (none when nothing can occlude); exact, no noise, spp
// ignored. Rect or environment lights, or indirect bounces: Monte Carlo with jittered pixel
// samples; at every vertex each area/environment light is sampled once and the BRDF once, combined
// with the power heuristic (multiple importance sampling); paths continue for max_bounces indirect
// bounces. Each pixel's random sequence is seeded from its index, so the image is the same at any
// thread count.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "cbrdf/image.h"
#include "render/material.h"
#include "render/scene.h"

namespace cbrdf::render {

struct RenderPlan {
  bool monte_carlo = false;
  bool shadow_rays = true;
  int spp = 1;
  int max_bounces = 0;
  std::vector<std::string> effects;  // one line each, for the log
};

// spp_override > 0 replaces the scene's spp (Monte Carlo only).
RenderPlan plan_render(const Scene& scene, int spp_override);

Image render(const Scene& scene, const std::vector<std::unique_ptr<Material>>& materials,
             const RenderPlan& plan, int threads);

}  // namespace cbrdf::render
