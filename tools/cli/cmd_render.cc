// SPDX-License-Identifier: MIT
// `cbrdf render`: renders a scene file (or a built-in scene) to OpenEXR and PNG, with the cheapest
// integrator that is exact for what the scene contains (render/integrator.h).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "cbrdf/image_io.h"
#include "cbrdf/metrics.h"
#include "cbrdf/parallel.h"
#include "cli.h"
#include "cli_io.h"
#include "render/builtin.h"
#include "render/integrator.h"
#include "render/material.h"
#include "render/scene.h"

namespace cbrdf::cli {
namespace {

struct RenderOptions {
  std::string scene, output, png, builtin, export_dir;
  bool list_builtins = false, brdf_timing = false;
  int spp = 0, threads = 0;
  double exposure = 0;
};

// Removes a directory when it goes out of scope (the temporary export of a built-in scene).
struct RemoveDir {
  std::filesystem::path dir;
  ~RemoveDir() {
    std::error_code ec;
    if (!dir.empty()) std::filesystem::remove_all(dir, ec);
  }
};

// The scene file and every file it reads, named for check_paths' messages.
std::vector<PathArg> scene_inputs(const render::Scene& scene,
                                  const std::filesystem::path& scene_path) {
  std::vector<PathArg> inputs = {{"scene", scene_path.string()}};
  for (const render::MaterialDesc& d : scene.materials) {
    if (!d.file.empty()) inputs.push_back({"material '" + d.name + "'", d.file.string()});
  }
  if (!scene.environment.file.empty()) {
    inputs.push_back({"environment", scene.environment.file.string()});
  }
  return inputs;
}

// Writes the OpenEXR and the tone-mapped PNG the options ask for.
Status write_images(const RenderOptions& o, const Context& ctx, const Image& image) {
  if (!o.output.empty()) {
    CBRDF_RETURN_IF_ERROR(write_exr(o.output, image));
    if (!ctx.quiet) std::printf("wrote %s\n", o.output.c_str());
  }
  if (!o.png.empty()) {
    const double e = o.exposure > 0 ? o.exposure : tonemap_exposure(image);
    CBRDF_RETURN_IF_ERROR(write_png(o.png, tonemap(image, e)));
    if (!ctx.quiet) std::printf("wrote %s (exposure %.4g)\n", o.png.c_str(), e);
  }
  return Status::ok_status();
}

int run_render(const RenderOptions& o, const Context& ctx) {
  if (o.list_builtins) {
    for (const render::BuiltinScene& b : render::builtin_scenes()) {
      std::printf("%-18s %s\n", b.name.c_str(), b.description.c_str());
    }
    return kExitOk;
  }
  if (o.builtin.empty() == o.scene.empty()) {
    return usage_error("render: give a SCENE.json or --builtin NAME (not both)");
  }
  if (!o.export_dir.empty() && o.builtin.empty())
    return usage_error("render: --export needs --builtin");
  if (o.output.empty() && o.png.empty() && o.export_dir.empty()) {
    return usage_error("render: give the output with -o OUT.exr and/or --png OUT.png");
  }
  const std::vector<PathArg> outputs = {{"-o", o.output}, {"--png", o.png}};
  if (auto bad =
          check_paths("render", {{"scene", o.scene}, {"--export", o.export_dir}}, outputs, false)) {
    return usage_error(*bad);
  }
  std::filesystem::path scene_path = o.scene;
  RemoveDir temporary;
  if (!o.builtin.empty()) {
    std::filesystem::path dir = o.export_dir;
    if (dir.empty()) {
      dir = std::filesystem::temp_directory_path() /
            ("cbrdf-builtin-" + std::to_string(::getpid()) + "-" + o.builtin);
      temporary.dir = dir;
    }
    auto exported = render::export_builtin(o.builtin, dir);
    if (!exported.ok()) return fail(exported.status());
    scene_path = *exported;
    if (!o.export_dir.empty() && !ctx.quiet) std::printf("wrote %s\n", scene_path.c_str());
    if (o.output.empty() && o.png.empty()) return kExitOk;
  }
  auto scene = render::load_scene(scene_path);
  if (!scene.ok()) return fail(scene.status());
  // The files the scene reads must survive the render too.
  if (auto bad = check_paths("render", scene_inputs(*scene, scene_path), outputs, false)) {
    return usage_error(*bad);
  }
  std::vector<std::unique_ptr<render::Material>> materials;
  for (const render::MaterialDesc& d : scene->materials) {
    auto m = render::Material::create(d);
    if (!m.ok())
      return fail(m.status().with_context(scene_path.string() + ": material '" + d.name + "'"));
    materials.push_back(std::move(*m));
  }
  const render::RenderPlan plan = render::plan_render(*scene, o.spp);
  const int threads = o.threads > 0 ? std::min(o.threads, thread_limit()) : thread_limit();
  if (!ctx.quiet) {
    std::printf("scene %s: %dx%d, %zu material(s)\n", scene_path.c_str(), scene->width,
                scene->height, materials.size());
    for (const std::string& e : plan.effects) std::printf("  simulated: %s\n", e.c_str());
    if (ctx.verbose) {
      for (const auto& m : materials)
        std::printf("  material %s: %s\n", m->name().c_str(), m->description().c_str());
    }
  }
  const auto start = std::chrono::steady_clock::now();
  const Image image = render::render(*scene, materials, plan, threads);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!ctx.quiet) {
    std::printf("rendered in %.3f s on %d thread(s), %d sample(s) per pixel\n", seconds, threads,
                plan.spp);
  }
  if (Status s = write_images(o, ctx, image); !s.ok()) return fail(s);
  if (o.brdf_timing) {
    for (const auto& m : materials) {
      std::printf("brdf eval %-20s %8.1f ns  (%s)\n", m->name().c_str(),
                  render::eval_cost_ns(*m, 200000), m->description().c_str());
    }
  }
  return kExitOk;
}

}  // namespace

void add_render_command(CLI::App& app, const Context& ctx, Action* action) {
  auto o = std::make_shared<RenderOptions>();
  CLI::App* cmd = app.add_subcommand(
      "render", "Render a scene (JSON) with MERL, .cbrdf or analytic materials to OpenEXR/PNG");
  cmd->add_option("scene", o->scene, "Scene file (.json); see tools/render/scene.h for the format");
  cmd->add_option("-o,--output", o->output, "Output OpenEXR (linear radiance)");
  cmd->add_option("--png", o->png, "Also write a tone-mapped PNG");
  cmd->add_option("--exposure", o->exposure,
                  "PNG exposure (default: the 99th percentile maps to 1)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--spp", o->spp, "Samples per pixel for Monte Carlo scenes (overrides the scene)")
      ->check(CLI::Range(1, 1 << 20));
  cmd->add_option("--threads", o->threads, "Render threads (default: all cores)")
      ->check(CLI::Range(1, 1024));
  cmd->add_option("--builtin", o->builtin, "Render a built-in scene (see --list-builtins)");
  cmd->add_option("--export", o->export_dir,
                  "With --builtin: write the scene and its assets into this directory");
  cmd->add_flag("--list-builtins", o->list_builtins, "List the built-in scenes");
  cmd->add_flag("--brdf-timing", o->brdf_timing,
                "After rendering, time one BRDF evaluation of each material");
  cmd->callback([o, &ctx, action] { *action = [o, &ctx] { return run_render(*o, ctx); }; });
}

}  // namespace cbrdf::cli
