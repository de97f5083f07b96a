// SPDX-License-Identifier: MIT
// The renderer's library (tools/render): scene loading and its errors, the integrator plan, a
// closed-form render, the mesh BVH against brute force, and images independent of the threads.
// tests/tools/render_cli_test.cc runs the `cbrdf render` command end to end.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "cbrdf/coords.h"
#include "cbrdf/parallel.h"
#include "cbrdf/samples.h"
#include "render/builtin.h"
#include "render/integrator.h"
#include "render/material.h"
#include "render/mesh.h"
#include "render/scene.h"
#include "render/table_lookup.h"
#include "table_builder.h"
#include "test_support.h"

namespace cbrdf::render {
namespace {

using testing::TempDir;
namespace fs = std::filesystem;

constexpr double kPi = std::numbers::pi;

void write(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
}

std::vector<std::unique_ptr<Material>> create_materials(const Scene& scene) {
  std::vector<std::unique_ptr<Material>> out;
  for (const MaterialDesc& d : scene.materials) {
    auto m = Material::create(d);
    EXPECT_TRUE(m.ok()) << m.status().message();
    if (m.ok()) out.push_back(std::move(*m));
  }
  return out;
}

Image render_scene(const Scene& scene, int threads, int spp_override = 0) {
  const auto materials = create_materials(scene);
  return render(scene, materials, plan_render(scene, spp_override), threads);
}

MaterialDesc lambertian_desc(const std::string& name, const Rgb& albedo) {
  MaterialDesc d;
  d.name = name;
  d.type = MaterialType::kAnalytic;
  d.lobes = {lambertian(albedo)};
  return d;
}

// ---- load_scene ---------------------------------------------------------------------------------

constexpr const char* kValidScene = R"({
  "image": {"width": 40, "height": 30, "spp": 8},
  "camera": {"type": "perspective", "position": [0, 1, 5], "look_at": [0, 0, 0], "fov_deg": 30},
  "materials": {"m": {"type": "analytic", "lobes": [{"kind": "lambertian", "rgb": 0.5}]},
                "g": {"type": "analytic", "lobes": [{"kind": "ggx", "rgb": [0.9, 0.6, 0.3], "alpha": 0.2}]}},
  "objects": [{"type": "sphere", "center": [0, 1, 0], "radius": 1, "material": "g"},
              {"type": "plane", "point": [0, 0, 0], "normal": [0, 2, 0], "material": "m"}],
  "lights": [{"type": "directional", "to_light": [0, 0, 3], "irradiance": [1, 2, 3]},
             {"type": "environment", "radiance": 0.25}],
  "integrator": {"max_bounces": 2}})";

TEST(RenderLoadScene, ReadsEveryPart) {
  TempDir tmp;
  write(tmp / "s.json", kValidScene);
  auto s = load_scene(tmp / "s.json");
  ASSERT_TRUE(s.ok()) << s.status().message();
  EXPECT_EQ(s->width, 40);
  EXPECT_EQ(s->height, 30);
  EXPECT_EQ(s->spp, 8);
  EXPECT_EQ(s->max_bounces, 2);
  EXPECT_FALSE(s->camera.orthographic);
  EXPECT_DOUBLE_EQ(s->camera.fov_deg, 30);
  ASSERT_EQ(s->materials.size(), 2u);
  ASSERT_EQ(s->spheres.size(), 1u);
  ASSERT_EQ(s->planes.size(), 1u);
  // Objects refer to materials by index into scene.materials.
  EXPECT_EQ(s->materials[std::size_t(s->spheres[0].material)].name, "g");
  EXPECT_EQ(s->materials[std::size_t(s->planes[0].material)].name, "m");
  // Directions are normalized.
  EXPECT_DOUBLE_EQ(s->planes[0].normal.y, 1);
  ASSERT_EQ(s->directionals.size(), 1u);
  EXPECT_DOUBLE_EQ(s->directionals[0].to_light.z, 1);
  EXPECT_TRUE(s->environment.present);
  EXPECT_TRUE(s->environment.uniform);
  EXPECT_DOUBLE_EQ(s->environment.radiance[1], 0.25);
}

struct BadScene {
  const char* json;
  ErrorCode code;
  const char* message;  // after "<file>: "
};

TEST(RenderLoadScene, ErrorsNameTheFileAndTheJsonPath) {
  const std::string camera =
      R"("camera": {"type": "orthographic", "position": [0, 0, 5], "look_at": [0, 0, 0], "height": 2})";
  const std::string mat =
      R"("materials": {"m": {"type": "analytic", "lobes": [{"kind": "lambertian", "rgb": 0.5}]}})";
  const std::string sphere =
      R"({"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"})";
  const std::string light = R"({"type": "directional", "to_light": [0, 0, 1], "irradiance": 1})";
  auto scene = [&](const std::string& objects, const std::string& lights = "",
                   const std::string& extra = "") {
    return "{" + camera + ", " + mat + ", \"objects\": [" + objects + "], \"lights\": [" +
           (lights.empty() ? light : lights) + "]" + extra + "}";
  };
  const std::vector<std::pair<std::string, BadScene>> cases = {
      {scene(sphere +
             R"(, {"type": "sphere", "center": [1, 0, 0], "radius": -1, "material": "m"})"),
       {"", ErrorCode::kInvalidArgument,
        "scene.objects[1].radius: expected a positive number, got -1"}},
      {scene(R"({"type": "sphere", "center": [0, 0], "radius": 1, "material": "m"})"),
       {"", ErrorCode::kInvalidArgument, "scene.objects[0].center: expected [x, y, z]"}},
      {scene(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "nope"})"),
       {"", ErrorCode::kInvalidArgument, "scene.objects[0].material: no material named 'nope'"}},
      {scene(R"({"type": "mesh", "file": "missing.drc", "material": "m"})"),
       {"", ErrorCode::kNotFound, "scene.objects[0].file: no such file"}},
      {scene(
           sphere,
           light +
               R"(, {"type": "rect", "corner": [0, 0, 0], "edge1": [1, 0, 0], "edge2": [2, 0, 0], "radiance": 1})"),
       {"", ErrorCode::kInvalidArgument, "scene.lights[1]: edge1 and edge2 span no area"}},
      {scene(sphere, R"({"type": "directional", "to_light": [0, 0, 0], "irradiance": 1})"),
       {"", ErrorCode::kInvalidArgument,
        "scene.lights[0].to_light: expected a non-zero direction"}},
      {scene(sphere, "", R"(, "integrator": {"max_bounces": 65})"),
       {"", ErrorCode::kInvalidArgument,
        "scene.integrator.max_bounces: expected an integer from 0 to 64, got 65"}},
      {scene(sphere, "", R"(, "colour": 1)"),
       {"", ErrorCode::kInvalidArgument, "scene.colour: unknown key"}},
      {R"({"camera": {"type": "fisheye", "position": [0, 0, 5], "look_at": [0, 0, 0]}, "objects": [], "lights": [{"type": "directional", "to_light": [0, 0, 1], "irradiance": 1}]})",
       {"", ErrorCode::kInvalidArgument,
        "scene.camera.type: expected perspective or orthographic, got 'fisheye'"}},
      {R"({"camera": {"type": "perspective", "position": [0, 0, 5], "look_at": [0, 0, 0]},
           "materials": {"m": {"type": "analytic", "lobes": [{"kind": "phong", "rgb": 1}]}},
           "objects": [], "lights": [{"type": "directional", "to_light": [0, 0, 1], "irradiance": 1}]})",
       {"", ErrorCode::kInvalidArgument,
        "scene.materials.m.lobes[0].kind: unknown lobe kind 'phong'"}},
  };
  TempDir tmp;
  for (const auto& [text, bad] : cases) {
    const fs::path file = tmp / "bad.json";
    write(file, text);
    auto s = load_scene(file);
    ASSERT_FALSE(s.ok()) << text;
    EXPECT_EQ(s.status().code(), bad.code) << s.status().message();
    const std::string want = file.string() + ": " + bad.message;
    EXPECT_EQ(s.status().message().substr(0, want.size()), want) << s.status().message();
  }
}

TEST(RenderLoadScene, MissingFileAndBadJson) {
  TempDir tmp;
  auto missing = load_scene(tmp / "none.json");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().code(), ErrorCode::kNotFound);
  EXPECT_NE(missing.status().message().find("none.json: no such file"), std::string::npos);

  write(tmp / "broken.json", "{\"camera\": [1, 2,");
  auto broken = load_scene(tmp / "broken.json");
  ASSERT_FALSE(broken.ok());
  EXPECT_EQ(broken.status().code(), ErrorCode::kCorrupt);
  EXPECT_NE(broken.status().message().find("broken.json: not valid JSON"), std::string::npos)
      << broken.status().message();
}

// ---- plan_render --------------------------------------------------------------------------------

Scene one_sphere_scene() {
  Scene s;
  s.width = 33;
  s.height = 33;
  s.spp = 7;
  s.camera.orthographic = true;
  s.camera.position = {0, 0, 5};
  s.camera.look_at = {0, 0, 0};
  s.camera.height = 2.4;
  s.materials = {lambertian_desc("m", {0.8, 0.5, 0.2})};
  s.spheres = {{{0, 0, 0}, 1.0, 0}};
  return s;
}

bool mentions(const RenderPlan& p, const std::string& text) {
  for (const std::string& e : p.effects) {
    if (e.find(text) != std::string::npos) return true;
  }
  return false;
}

TEST(RenderPlan, DeltaLightsOnlyIsExactWithoutSampling) {
  Scene s = one_sphere_scene();
  s.directionals = {{{0, 0, 1}, {1, 1, 1}}};
  const RenderPlan p = plan_render(s, 64);
  EXPECT_FALSE(p.monte_carlo);
  EXPECT_EQ(p.spp, 1);          // the override does not apply to an exact render
  EXPECT_FALSE(p.shadow_rays);  // a lone sphere cannot occlude itself
  EXPECT_TRUE(mentions(p, "shadows: none traced"));
  EXPECT_TRUE(mentions(p, "indirect light: none"));

  s.planes = {{{0, -1, 0}, {0, 1, 0}, 0}};
  EXPECT_TRUE(plan_render(s, 0).shadow_rays);  // two objects can shadow each other
  EXPECT_FALSE(plan_render(s, 0).monte_carlo);
}

TEST(RenderPlan, MeshesNeedShadowRaysEvenAlone) {
  Scene s = one_sphere_scene();
  s.spheres.clear();
  auto mesh = std::make_shared<TriangleMesh>();
  mesh->positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh->triangles = {{0, 1, 2}};
  mesh->finalize(1, {0, 0, 0});
  s.meshes = {{mesh, 0}};
  s.points = {{{0, 0, 3}, {1, 1, 1}}};
  EXPECT_TRUE(plan_render(s, 0).shadow_rays);  // a mesh can be concave
}

TEST(RenderPlan, AreaEnvironmentAndBouncesAskForMonteCarlo) {
  Scene env = one_sphere_scene();
  env.environment.present = true;
  RenderPlan p = plan_render(env, 0);
  EXPECT_TRUE(p.monte_carlo);
  EXPECT_EQ(p.spp, 7);                    // the scene's spp
  EXPECT_EQ(plan_render(env, 3).spp, 3);  // --spp overrides it
  EXPECT_TRUE(mentions(p, "environment (uniform)"));
  EXPECT_TRUE(mentions(p, "MIS"));

  Scene rect = one_sphere_scene();
  rect.rects = {{{-1, 3, -1}, {2, 0, 0}, {0, 0, 2}, {1, 1, 1}}};
  p = plan_render(rect, 0);
  EXPECT_TRUE(p.monte_carlo);
  EXPECT_TRUE(p.shadow_rays);  // the light itself is geometry
  EXPECT_TRUE(mentions(p, "1 rect light(s)"));

  Scene bounce = one_sphere_scene();
  bounce.directionals = {{{0, 0, 1}, {1, 1, 1}}};
  bounce.max_bounces = 2;
  p = plan_render(bounce, 0);
  EXPECT_TRUE(p.monte_carlo);
  EXPECT_EQ(p.max_bounces, 2);
  EXPECT_TRUE(mentions(p, "indirect light: 2 bounce(s)"));
}

// ---- a closed form ------------------------------------------------------------------------------

// A Lambertian sphere under a directional light seen by an orthographic camera: the centre pixel's
// ray meets the sphere at (0, 0, 1) with normal +z, so L = albedo / pi * E * cos(theta_i) exactly.
TEST(RenderImage, LambertianSphereCentrePixelMatchesClosedForm) {
  Scene s = one_sphere_scene();
  const Vec3 to_light = normalize(Vec3{0.3, 0.5, 0.8});
  s.directionals = {{to_light, {2, 3, 4}}};
  const Image img = render_scene(s, 2);
  ASSERT_EQ(img.width, 33);
  ASSERT_EQ(img.height, 33);
  const double albedo[3] = {0.8, 0.5, 0.2}, e[3] = {2, 3, 4};
  for (int c = 0; c < 3; ++c) {
    const double expected = albedo[c] / kPi * e[c] * to_light.z;
    EXPECT_NEAR(img.at(16, 16, c), expected, 1e-6 * expected) << c;
    EXPECT_EQ(img.at(0, 0, c), 0.0f);  // background, no environment
  }
  // Pixel (20, 16) sees the sphere at x = 0.29, y = 0: normal (x, 0, sqrt(1 - x^2)).
  const double x = ((20 + 0.5) / 33 * 2 - 1) * 2.4 / 2;
  const double cos_i = x * to_light.x + std::sqrt(1 - x * x) * to_light.z;
  EXPECT_NEAR(img.at(20, 16, 0), albedo[0] / kPi * e[0] * cos_i, 1e-6);
}

// A white Lambertian sphere in a uniform white environment (furnace): every pixel on the sphere
// converges to the environment's radiance; the estimator is unbiased, so the mean is close to 1.
TEST(RenderImage, WhiteFurnaceConvergesToTheEnvironment) {
  Scene s = one_sphere_scene();
  s.materials = {lambertian_desc("white", {1, 1, 1})};
  s.environment.present = true;
  s.environment.radiance = {1, 1, 1};
  const Image img = render_scene(s, 0, 64);
  double sum = 0;
  int n = 0;
  for (int y = 12; y <= 20; ++y) {
    for (int x = 12; x <= 20; ++x) {
      sum += img.at(x, y, 1);
      ++n;
    }
  }
  EXPECT_NEAR(sum / n, 1.0, 0.02);
  EXPECT_FLOAT_EQ(img.at(0, 0, 0), 1.0f);  // the environment seen directly
}

// ---- the mesh BVH -------------------------------------------------------------------------------

// Moller-Trumbore over every triangle: the nearest t in (t_min, t_max), or +inf.
double brute_force_hit(const TriangleMesh& m, const Ray& r, double t_min, double t_max,
                       int* triangle) {
  double best = t_max;
  *triangle = -1;
  for (std::size_t i = 0; i < m.triangles.size(); ++i) {
    const Vec3& p0 = m.positions[m.triangles[i][0]];
    const Vec3 e1 = m.positions[m.triangles[i][1]] - p0, e2 = m.positions[m.triangles[i][2]] - p0;
    const Vec3 pv = cross(r.dir, e2);
    const double det = dot(e1, pv);
    if (det == 0) continue;
    const Vec3 tv = r.origin - p0;
    const double u = dot(tv, pv) / det;
    const Vec3 qv = cross(tv, e1);
    const double v = dot(r.dir, qv) / det;
    const double t = dot(e2, qv) / det;
    if (u >= 0 && v >= 0 && u + v <= 1 && t > t_min && t < best) {
      best = t;
      *triangle = int(i);
    }
  }
  return *triangle >= 0 ? best : std::numeric_limits<double>::infinity();
}

TEST(RenderMesh, BvhMatchesBruteForceOnRandomRays) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  // 600 small triangles scattered in a box: a deep enough BVH with overlapping nodes.
  TriangleMesh mesh;
  for (int i = 0; i < 600; ++i) {
    const Vec3 c{u(rng), u(rng), u(rng)};
    const auto base = std::uint32_t(mesh.positions.size());
    for (int k = 0; k < 3; ++k) mesh.positions.push_back(c + Vec3{u(rng), u(rng), u(rng)} * 0.15);
    mesh.triangles.push_back({base, base + 1, base + 2});
  }
  mesh.finalize(2.0, {0.5, -0.25, 1});  // the BVH is built over the transformed positions
  const Vec3 centre{0.5, -0.25, 1};
  int hits = 0;
  for (int i = 0; i < 4000; ++i) {
    Ray r;
    r.origin = centre + Vec3{u(rng), u(rng), u(rng)} * 4.0;
    // Every tenth ray is axis-aligned (a zero direction component: infinite inverse).
    const Vec3 target = centre + Vec3{u(rng), u(rng), u(rng)} * 2.0;
    r.dir =
        i % 10 == 0 ? Vec3{0, 0, target.z > r.origin.z ? 1.0 : -1.0} : normalize(target - r.origin);
    const double t_min = i % 3 == 0 ? 0.5 : 0.0;
    int want_tri = -1;
    const double want = brute_force_hit(mesh, r, t_min, 1e30, &want_tri);
    MeshHit hit;
    hit.t = 1e30;
    const bool found = mesh.intersect(r, t_min, &hit);
    ASSERT_EQ(found, want_tri >= 0) << "ray " << i;
    if (!found) continue;
    ++hits;
    EXPECT_NEAR(hit.t, want, 1e-9 * want) << "ray " << i;
    EXPECT_EQ(hit.triangle, want_tri) << "ray " << i;
    // Any-hit queries agree: blocked before the nearest hit's far side, free before it.
    EXPECT_TRUE(mesh.occluded(r, t_min, want * (1 + 1e-9) + 1e-12)) << "ray " << i;
    EXPECT_FALSE(mesh.occluded(r, t_min, want * (1 - 1e-9))) << "ray " << i;
  }
  EXPECT_GT(hits, 1000);  // the test exercises hits, not only misses
}

// ---- threads ------------------------------------------------------------------------------------

// Monte Carlo with every light kind and a bounce: per-pixel seeds make the image the same for any
// thread count and any runner.
TEST(RenderImage, IdenticalAtAnyThreadCountAndRunner) {
  Scene s;
  s.width = 24;
  s.height = 17;
  s.spp = 3;
  s.max_bounces = 1;
  s.camera.position = {0, 1.5, 5};
  s.camera.look_at = {0, 0.4, 0};
  s.camera.fov_deg = 45;
  MaterialDesc glossy;
  glossy.name = "glossy";
  glossy.type = MaterialType::kAnalytic;
  glossy.lobes = {lambertian({0.3, 0.2, 0.1}), ggx({0.9, 0.8, 0.7}, 0.25)};
  s.materials = {glossy, lambertian_desc("floor", {0.5, 0.5, 0.5})};
  s.spheres = {{{-0.6, 0.5, 0}, 0.5, 0}, {{0.6, 0.5, 0}, 0.5, 0}};
  s.planes = {{{0, 0, 0}, {0, 1, 0}, 1}};
  s.points = {{{1, 3, 2}, {10, 10, 10}}};
  s.rects = {{{-0.5, 2.5, -0.5}, {1, 0, 0}, {0, 0, 1}, {4, 4, 4}}};
  s.environment.present = true;
  s.environment.radiance = {0.2, 0.3, 0.4};

  const Image one = render_scene(s, 1);
  ASSERT_EQ(one.width, 24);
  double total = 0;
  for (float v : one.data) total += v;
  EXPECT_GT(total, 0);
  EXPECT_EQ(render_scene(s, 2).data, one.data);
  EXPECT_EQ(render_scene(s, 5).data, one.data);
  set_thread_limit(3);
  EXPECT_EQ(render_scene(s, 0).data, one.data);
  // A runner that runs the rows backwards.
  set_parallel_runner([](int tasks, const std::function<void(int)>& body) {
    for (int t = tasks - 1; t >= 0; --t) body(t);
  });
  EXPECT_EQ(render_scene(s, 0).data, one.data);
  set_parallel_runner(nullptr);
  set_thread_limit(0);
}

// A measured built-in sample has no analytic form: a scene's {"type": "sample"} material looks up
// its MERL table, as a "merl" material of the same table would.
TEST(RenderMaterial, MeasuredSampleLooksUpItsTable) {
  MaterialDesc d;
  d.name = "metal";
  d.type = MaterialType::kSample;
  d.sample_name = "nickel";
  auto m = Material::create(d);
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ((*m)->description(), "measured sample 'nickel', nearest-bin lookup");
  const BrdfTable table = make_sample("nickel").value();
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 100; ++i) {
    const Vec3 wi = sample_cosine_hemisphere(u(rng), u(rng));
    const Vec3 wo = sample_cosine_hemisphere(u(rng), u(rng));
    double got[3], want[3];
    (*m)->eval(wi, wo, got);
    lookup_nearest(table, wi, wo, want);
    for (int c = 0; c < 3; ++c) ASSERT_EQ(got[c], want[c]) << i;
  }
  d.sample_name = "gold-leaf";
  const auto unknown = Material::create(d);
  ASSERT_FALSE(unknown.ok());
  EXPECT_TRUE(testing::contains(unknown.status().message(), "material 'metal': unknown sample"))
      << unknown.status().message();
}

// Trilinear lookup: at a bin's own position it returns the bin; between bins it interpolates
// linearly (a table linear in the bin indices is reproduced exactly); not-measured neighbours are
// skipped and the other weights renormalised, so a constant table stays constant up to the horizon.
TEST(RenderTableLookup, TrilinearIsExactOnLinearTablesAndSkipsUnmeasuredBins) {
  const auto f = [](int c, int h, int d, int p) {
    return 0.5 + c + 0.01 * h + 0.02 * d + 0.003 * p;
  };
  const BrdfTable linear = testing::make_table(f, /*horizon_mask=*/false);
  double rgb[3];
  lookup_trilinear_measured(linear, GridPosition{12, 30, 40}, rgb);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(rgb[c], f(c, 12, 30, 40), 1e-12);
  lookup_trilinear_measured(linear, GridPosition{12.25, 30.5, 40.75}, rgb);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(rgb[c], 0.5 + c + 0.01 * 12.25 + 0.02 * 30.5 + 0.003 * 40.75, 1e-12);
  }
  // phi_d wraps: halfway between bin 179 and bin 0.
  lookup_trilinear_measured(linear, GridPosition{12, 30, 179.5}, rgb);
  EXPECT_NEAR(rgb[0], (f(0, 12, 30, 179) + f(0, 12, 30, 0)) / 2, 1e-12);

  // One of the 8 neighbours not measured (in channel 0 only): the other 7 carry the value.
  BrdfTable constant = testing::make_table([](int, int, int, int) { return 2.0; }, false);
  constant.set_stored(0, merl_index(13, 31, 41), -1.0);
  lookup_trilinear_measured(constant, GridPosition{12.5, 30.5, 40.5}, rgb);
  EXPECT_NEAR(rgb[0], 2.0, 1e-12);
  EXPECT_NEAR(rgb[1], 2.0, 1e-12);
  // cbrdf::lookup_linear reads it as 0 instead: 7/8 of the value.
  Vec3 wi, wo;
  from_half_diff({theta_h_of(12.5), 0.3, theta_d_of(30.5), phi_d_of(40.5)}, &wi, &wo);
  lookup_linear(constant, wi, wo, rgb);
  EXPECT_NEAR(rgb[0], 2.0 * 7 / 8, 1e-6);
  lookup_trilinear_measured(constant, wi, wo, rgb);
  EXPECT_NEAR(rgb[0], 2.0, 1e-9);
  // All 8 not measured: 0.
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      for (int e = 0; e < 2; ++e) constant.set_not_measured(merl_index(12 + a, 30 + b, 40 + e));
  lookup_trilinear_measured(constant, GridPosition{12.5, 30.5, 40.5}, rgb);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(rgb[c], 0.0);
}

// With the real horizon mask, a constant table reads constant at every direction pair above the
// horizon (nearest-bin lookup returns 0 where its one bin is not measured).
TEST(RenderTableLookup, ConstantTableStaysConstantNearTheHorizon) {
  const BrdfTable t = testing::make_table([](int, int, int, int) { return 1.5; });
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 2000; ++i) {
    const Vec3 wi = sample_cosine_hemisphere(u(rng), u(rng));
    const Vec3 wo = sample_cosine_hemisphere(u(rng), u(rng));
    double rgb[3];
    lookup_trilinear_measured(t, wi, wo, rgb);
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(rgb[c], 1.5, 1e-9) << i;
  }
}

// A "merl" material with "lookup": "linear" and Material::from_table use the trilinear lookup.
TEST(RenderTableLookup, MaterialsUseIt) {
  const BrdfTable t = make_sample("nickel").value();
  const auto tri = Material::from_table("m", t, true);
  const auto near = Material::from_table("m", t, false);
  EXPECT_EQ(tri->description(), "measured table, trilinear lookup");
  EXPECT_EQ(near->description(), "measured table, nearest-bin lookup");
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int differ = 0;
  for (int i = 0; i < 200; ++i) {
    const Vec3 wi = sample_cosine_hemisphere(u(rng), u(rng));
    const Vec3 wo = sample_cosine_hemisphere(u(rng), u(rng));
    double got[3], want[3], nearest[3];
    tri->eval(wi, wo, got);
    lookup_trilinear_measured(t, wi, wo, want);
    near->eval(wi, wo, nearest);
    for (int c = 0; c < 3; ++c) ASSERT_EQ(got[c], want[c]);
    differ += got[0] != nearest[0];
  }
  EXPECT_GT(differ, 150);
}

// figure4_one_material has the exported figure4 scene's image, camera, spheres and light.
TEST(RenderBuiltin, Figure4OneMaterialMatchesTheFigure4Scene) {
  TempDir tmp;
  auto path = export_builtin("figure4-reference", tmp.path());
  ASSERT_TRUE(path.ok()) << path.status().message();
  auto ref = load_scene(*path);
  ASSERT_TRUE(ref.ok()) << ref.status().message();
  MaterialDesc d;
  d.name = "m";
  const Scene s = figure4_one_material(d, 1.0);
  EXPECT_EQ(s.width, ref->width);
  EXPECT_EQ(s.height, ref->height);
  EXPECT_EQ(s.camera.orthographic, ref->camera.orthographic);
  EXPECT_EQ(s.camera.height, ref->camera.height);
  ASSERT_EQ(s.spheres.size(), ref->spheres.size());
  for (std::size_t i = 0; i < s.spheres.size(); ++i) {
    EXPECT_NEAR(s.spheres[i].center.x, ref->spheres[i].center.x, 1e-6);
    EXPECT_EQ(s.spheres[i].material, 0);
  }
  ASSERT_EQ(s.directionals.size(), 1u);
  ASSERT_EQ(ref->directionals.size(), 1u);
  EXPECT_NEAR(dot(s.directionals[0].to_light, ref->directionals[0].to_light), 1.0, 1e-12);
  EXPECT_EQ(s.directionals[0].irradiance, ref->directionals[0].irradiance);
  const Scene half = figure4_one_material(d, 0.5);
  EXPECT_EQ(half.width, 660);
  EXPECT_EQ(half.height, 120);
}

}  // namespace
}  // namespace cbrdf::render
