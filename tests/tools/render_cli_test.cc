// SPDX-License-Identifier: MIT
// `cbrdf render` and `cbrdf imgdiff` end to end: closed forms, furnace tests, determinism, meshes,
// the built-in scenes and scene errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <string>

#include "cbrdf/analytic.h"
#include "cbrdf/image_io.h"
#include "test_support.h"

namespace cbrdf {
namespace {

using testing::run_cli;
using testing::TempDir;
namespace fs = std::filesystem;

constexpr double kPi = std::numbers::pi;
const fs::path kScenes = fs::path(CBRDF_TEST_DATA_DIR) / "scenes";

void write(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
}

std::string q(const fs::path& p) {
  return "'" + p.string() + "'";
}

Image render_ok(const fs::path& scene, const fs::path& out, const std::string& extra = "",
                std::string* log = nullptr) {
  const auto r = run_cli("render " + q(scene) + " -o " + q(out) + " " + extra);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  if (log != nullptr) *log = r.out;
  auto img = read_exr(out);
  EXPECT_TRUE(img.ok()) << img.status().message();
  return img.ok() ? *img : Image();
}

// The orthographic camera looking down -z from z = 5 with view height h: pixel centre -> (x, y).
void ortho_point(int px, int py, int w, int h, double height, double* x, double* y) {
  const double aspect = double(w) / h;
  *x = (((px + 0.5) / w) * 2 - 1) * aspect * height / 2;
  *y = (1 - ((py + 0.5) / h) * 2) * height / 2;
}

TEST(RenderCli, LambertianSphereUnderDirectionalLightMatchesClosedForm) {
  TempDir tmp;
  const int w = 96, h = 64;
  write(tmp / "s.json", R"({
    "image": {"width": 96, "height": 64},
    "camera": {"type": "orthographic", "position": [0, 0, 5], "look_at": [0, 0, 0], "height": 2.4},
    "materials": {"m": {"type": "analytic", "lobes": [{"kind": "lambertian", "rgb": [0.8, 0.5, 0.2]}]}},
    "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}],
    "lights": [{"type": "directional", "to_light": [0.3, 0.5, 0.8], "irradiance": [2, 3, 4]}]})");
  std::string log;
  const Image img = render_ok(tmp / "s.json", tmp / "s.exr", "", &log);
  ASSERT_EQ(img.width, w);
  ASSERT_EQ(img.height, h);
  EXPECT_NE(log.find("shadows: none traced"), std::string::npos) << log;
  EXPECT_NE(log.find("indirect light: none"), std::string::npos) << log;
  const double ll = std::sqrt(0.09 + 0.25 + 0.64);
  const double lx = 0.3 / ll, ly = 0.5 / ll, lz = 0.8 / ll;
  const double albedo[3] = {0.8, 0.5, 0.2}, e[3] = {2, 3, 4};
  int lit = 0;
  for (int py = 0; py < h; ++py) {
    for (int px = 0; px < w; ++px) {
      double x, y;
      ortho_point(px, py, w, h, 2.4, &x, &y);
      const double r2 = x * x + y * y;
      if (std::abs(r2 - 1) < 1e-6) continue;  // a pixel centre on the silhouette
      const double cos_i = r2 < 1 ? x * lx + y * ly + std::sqrt(1 - r2) * lz : 0;
      for (int c = 0; c < 3; ++c) {
        const double expected = cos_i > 0 ? albedo[c] / kPi * e[c] * cos_i : 0.0;
        EXPECT_NEAR(img.at(px, py, c), expected, 1e-6 + 1e-5 * expected) << px << "," << py;
      }
      lit += cos_i > 0;
    }
  }
  EXPECT_GT(lit, 1000);
}

const char* kDeltaScene = R"({
    "image": {"width": 80, "height": 60, "spp": 4},
    "camera": {"type": "perspective", "position": [0, 1.5, 5], "look_at": [0, 0.3, 0], "fov_deg": 45},
    "materials": {"a": {"type": "sample", "name": "plastic"},
                  "b": {"type": "analytic", "lobes": [{"kind": "lambertian", "rgb": 0.5}]}},
    "objects": [{"type": "sphere", "center": [-0.6, 0.5, 0], "radius": 0.5, "material": "a"},
                {"type": "sphere", "center": [0.6, 0.5, 0], "radius": 0.5, "material": "a"},
                {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "material": "b"}],
    "lights": [{"type": "point", "position": [1, 3, 2], "intensity": 10},
               {"type": "directional", "to_light": [-0.5, 1, 0.3], "irradiance": [1, 0.8, 0.6]}]})";

TEST(RenderCli, DeltaLightPathIsIdenticalAtAnySppAndThreadCount) {
  TempDir tmp;
  write(tmp / "s.json", kDeltaScene);
  std::string log;
  const Image a = render_ok(tmp / "s.json", tmp / "a.exr", "--spp 1 --threads 1", &log);
  const Image b = render_ok(tmp / "s.json", tmp / "b.exr", "--spp 64 --threads 2");
  ASSERT_FALSE(a.empty());
  EXPECT_TRUE(a == b);
  EXPECT_NE(log.find("one shadow ray per delta light"), std::string::npos) << log;
  EXPECT_NE(log.find("does not depend on --spp"), std::string::npos) << log;
  // Shadows are there: the floor between the spheres and below them is darker than far away.
  double max_v = 0;
  for (float v : a.data) max_v = std::max(max_v, double(v));
  EXPECT_GT(max_v, 0.1);
}

TEST(RenderCli, MonteCarloIsReproducibleAcrossThreadCounts) {
  TempDir tmp;
  write(tmp / "s.json", R"({
    "image": {"width": 40, "height": 30, "spp": 4},
    "camera": {"type": "perspective", "position": [0, 1, 4], "look_at": [0, 0.3, 0]},
    "materials": {"a": {"type": "sample", "name": "ggx-rough"}},
    "objects": [{"type": "sphere", "center": [0, 0.5, 0], "radius": 0.5, "material": "a"},
                {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "material": "a"}],
    "lights": [{"type": "rect", "corner": [-1, 2, -1], "edge1": [0, 0, 2], "edge2": [2, 0, 0], "radiance": 5}],
    "integrator": {"max_bounces": 2}})");
  std::string log;
  const Image a = render_ok(tmp / "s.json", tmp / "a.exr", "--threads 1", &log);
  const Image b = render_ok(tmp / "s.json", tmp / "b.exr", "--threads 2");
  EXPECT_TRUE(a == b);
  EXPECT_NE(log.find("Monte Carlo with MIS"), std::string::npos) << log;
  EXPECT_NE(log.find("indirect light: 2 bounce(s)"), std::string::npos) << log;
}

// Furnace: a white Lambertian sphere under a uniform unit environment reflects radiance 1.
void expect_furnace(const std::string& env_light, const fs::path& dir) {
  write(dir / "s.json", R"({
    "image": {"width": 32, "height": 32, "spp": 256},
    "camera": {"type": "orthographic", "position": [0, 0, 5], "look_at": [0, 0, 0], "height": 2.2},
    "materials": {"white": {"type": "analytic", "lobes": [{"kind": "lambertian", "rgb": 1}]}},
    "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "white"}],
    "lights": [)" + env_light +
                            "]}");
  const Image img = render_ok(dir / "s.json", dir / "s.exr");
  double sum = 0, worst = 0;
  int n = 0;
  for (int py = 0; py < 32; ++py) {
    for (int px = 0; px < 32; ++px) {
      double x, y;
      ortho_point(px, py, 32, 32, 2.2, &x, &y);
      if (x * x + y * y > 0.95) continue;  // keep away from the silhouette's mixed pixels
      for (int c = 0; c < 3; ++c) {
        sum += img.at(px, py, c);
        worst = std::max(worst, std::abs(img.at(px, py, c) - 1.0));
        ++n;
      }
    }
  }
  ASSERT_GT(n, 1500);
  EXPECT_NEAR(sum / n, 1.0, 0.01);
  EXPECT_LT(worst, 0.2);
}

TEST(RenderCli, FurnaceLambertianUnderUniformEnvironment) {
  TempDir tmp;
  expect_furnace(R"({"type": "environment", "radiance": 1})", tmp.path());
}

// The same through the environment-map path: a constant EXR map.
TEST(RenderCli, FurnaceLambertianUnderConstantEnvironmentMap) {
  TempDir tmp;
  Image map(16, 8);
  for (float& v : map.data) v = 0.5f;
  ASSERT_TRUE(write_exr(tmp / "env.exr", map).ok());
  expect_furnace(R"({"type": "environment", "file": "env.exr", "scale": 2})", tmp.path());
}

// A GGX lobe (F0 = 1) on a plane seen at 60 degrees under a uniform unit environment: every pixel
// shows the lobe's directional albedo.
TEST(RenderCli, FurnaceGgxPlaneShowsDirectionalAlbedo) {
  TempDir tmp;
  const double t = 60 * kPi / 180;
  write(tmp / "s.json", R"({
    "image": {"width": 24, "height": 24, "spp": 256},
    "camera": {"type": "orthographic", "position": [0, )" +
                            std::to_string(5 * std::cos(t)) + ", " +
                            std::to_string(5 * std::sin(t)) +
                            R"(], "look_at": [0, 0, 0], "height": 1},
    "materials": {"g": {"type": "analytic", "lobes": [{"kind": "ggx", "rgb": 1, "alpha": 0.3}]}},
    "objects": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "material": "g"}],
    "lights": [{"type": "environment", "radiance": 1}]})");
  const Image img = render_ok(tmp / "s.json", tmp / "s.exr");
  const AnalyticBrdf brdf{{ggx({1, 1, 1}, 0.3)}};
  const Vec3 wo{std::sin(t), 0, std::cos(t)};
  const double expected = directional_albedo(brdf, wo)[0];
  double sum = 0;
  for (float v : img.data) sum += v;
  const double mean = sum / img.data.size();
  EXPECT_GT(expected, 0.5);
  EXPECT_LT(expected, 1.0);  // GGX loses energy to single scattering
  EXPECT_NEAR(mean, expected, 0.01 * expected) << "directional albedo " << expected;
}

// Lambert's polygon formula: irradiance at a point with normal n from a uniformly emitting polygon.
double polygon_irradiance(const std::vector<Vec3>& verts, const Vec3& p, const Vec3& n, double l) {
  double sum = 0;
  for (std::size_t i = 0; i < verts.size(); ++i) {
    Vec3 a{verts[i].x - p.x, verts[i].y - p.y, verts[i].z - p.z};
    const Vec3& vb = verts[(i + 1) % verts.size()];
    Vec3 b{vb.x - p.x, vb.y - p.y, vb.z - p.z};
    const double la = std::sqrt(dot(a, a)), lb = std::sqrt(dot(b, b));
    a = {a.x / la, a.y / la, a.z / la};
    b = {b.x / lb, b.y / lb, b.z / lb};
    const double gamma = std::acos(std::clamp(dot(a, b), -1.0, 1.0));
    Vec3 c{a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
    const double lc = std::sqrt(dot(c, c));
    sum += gamma * dot(c, n) / lc;
  }
  return l / 2 * std::abs(sum);
}

// A rect light over a Lambertian floor (light and BRDF samples with MIS) against the closed form.
TEST(RenderCli, RectLightOnLambertianFloorMatchesPolygonFormula) {
  TempDir tmp;
  write(tmp / "s.json", R"({
    "image": {"width": 16, "height": 16, "spp": 512},
    "camera": {"type": "orthographic", "position": [0, 5, 0], "look_at": [0, 0, 0], "up": [0, 0, -1], "height": 2},
    "materials": {"m": {"type": "analytic", "lobes": [{"kind": "lambertian", "rgb": 0.7}]}},
    "objects": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "material": "m"}],
    "lights": [{"type": "rect", "corner": [-0.5, 1, -0.25], "edge1": [1, 0, 0], "edge2": [0, 0, 0.5], "radiance": 3}]})");
  // The camera sits above the light: the light is hit first in the middle. Render only the floor:
  // the pixels outside the light's footprint.
  const Image img = render_ok(tmp / "s.json", tmp / "s.exr");
  const std::vector<Vec3> rect = {
      {-0.5, 1, -0.25}, {0.5, 1, -0.25}, {0.5, 1, 0.25}, {-0.5, 1, 0.25}};
  double err = 0, ref = 0;
  int n = 0;
  for (int py = 0; py < 16; ++py) {
    for (int px = 0; px < 16; ++px) {
      // Camera right = forward x up = (0,-1,0) x (0,0,-1) = (1, 0, 0); up = (0, 0, -1).
      const double x = ((px + 0.5) / 16 * 2 - 1), z = -(1 - (py + 0.5) / 16 * 2);
      if (std::abs(x) <= 0.55 && std::abs(z) <= 0.3) continue;
      const double e = polygon_irradiance(rect, {x, 0, z}, {0, 1, 0}, 3);
      const double expected = 0.7 / kPi * e;
      err += std::abs(img.at(px, py, 1) - expected);
      ref += expected;
      ++n;
    }
  }
  ASSERT_GT(n, 100);
  EXPECT_LT(err / ref, 0.03);  // mean relative error over the floor pixels
}

TEST(RenderCli, ObjMeshRendersItsExactSilhouetteAndShading) {
  TempDir tmp;
  // A unit cube centred at the origin, seen straight on: a square with the +z face's shading.
  write(tmp / "cube.obj", R"(v -0.5 -0.5 -0.5
v 0.5 -0.5 -0.5
v 0.5 0.5 -0.5
v -0.5 0.5 -0.5
v -0.5 -0.5 0.5
v 0.5 -0.5 0.5
v 0.5 0.5 0.5
v -0.5 0.5 0.5
f 1 3 2
f 1 4 3
f 5 6 7
f 5 7 8
f 1 2 6
f 1 6 5
f 4 8 7
f 4 7 3
f 1 5 8
f 1 8 4
f 2 3 7
f 2 7 6
)");
  write(tmp / "s.json", R"({
    "image": {"width": 40, "height": 40},
    "camera": {"type": "orthographic", "position": [0, 0, 5], "look_at": [0, 0, 0], "height": 2},
    "materials": {"m": {"type": "analytic", "lobes": [{"kind": "lambertian", "rgb": 0.6}]}},
    "objects": [{"type": "mesh", "file": "cube.obj", "material": "m", "scale": 1.2}],
    "lights": [{"type": "directional", "to_light": [0, 0.6, 0.8], "irradiance": 2}]})");
  const Image img = render_ok(tmp / "s.json", tmp / "s.exr");
  ASSERT_EQ(img.width, 40);
  const double face = 0.6 / kPi * 2 * 0.8;
  for (int py = 0; py < 40; ++py) {
    for (int px = 0; px < 40; ++px) {
      double x, y;
      ortho_point(px, py, 40, 40, 2, &x, &y);
      const bool inside = std::abs(x) < 0.6 && std::abs(y) < 0.6;
      EXPECT_NEAR(img.at(px, py, 0), inside ? face : 0.0, 1e-5) << px << "," << py;
    }
  }
}

TEST(RenderCli, DracoMeshMatchesTheAnalyticSphere) {
  TempDir tmp;
  const auto ex = run_cli("render --builtin mesh-env --export " + q(tmp / "assets"));
  ASSERT_EQ(ex.exit_code, 0) << ex.err;
  ASSERT_TRUE(fs::exists(tmp / "assets" / "icosphere.drc"));
  auto scene = [&](const std::string& object) {
    return R"({
    "image": {"width": 64, "height": 64},
    "camera": {"type": "orthographic", "position": [0, 0, 5], "look_at": [0, 0, 0], "height": 2.2},
    "materials": {"m": {"type": "analytic", "lobes": [{"kind": "lambertian", "rgb": 0.6}]}},
    "objects": [)" +
           object + R"(],
    "lights": [{"type": "directional", "to_light": [0, 0, 1], "irradiance": 1}]})";
  };
  write(tmp / "mesh.json",
        scene(R"({"type": "mesh", "file": "assets/icosphere.drc", "material": "m"})"));
  write(tmp / "sphere.json",
        scene(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"})"));
  const Image mesh = render_ok(tmp / "mesh.json", tmp / "mesh.exr");
  const Image sphere = render_ok(tmp / "sphere.json", tmp / "sphere.exr");
  ASSERT_EQ(mesh.width, 64);
  int covered_mesh = 0, covered_sphere = 0;
  double diff = 0, total = 0;
  for (int py = 0; py < 64; ++py) {
    for (int px = 0; px < 64; ++px) {
      covered_mesh += mesh.at(px, py, 0) > 0;
      covered_sphere += sphere.at(px, py, 0) > 0;
      diff += std::abs(mesh.at(px, py, 0) - sphere.at(px, py, 0));
      total += sphere.at(px, py, 0);
    }
  }
  // An inscribed 1280-triangle icosphere covers slightly less than the disc.
  EXPECT_GT(covered_sphere, 2500);
  EXPECT_LE(covered_mesh, covered_sphere + 2);
  EXPECT_GT(covered_mesh, covered_sphere * 0.97);
  EXPECT_LT(diff / total, 0.03);  // smooth Draco normals shade like the sphere
}

TEST(RenderCli, BuiltinScenesRenderAndFigure4ModelsMatchTheirReferences) {
  TempDir tmp;
  std::string log;
  const Image model = render_ok(kScenes / "figure4.json", tmp / "m.exr", "", &log);
  const Image ref = render_ok(kScenes / "figure4-reference.json", tmp / "r.exr");
  ASSERT_FALSE(model.empty());
  EXPECT_EQ(model.width, ref.width);
  const auto d =
      run_cli("imgdiff " + q(tmp / "r.exr") + " " + q(tmp / "m.exr") + " -o " + q(tmp / "d.png"));
  ASSERT_EQ(d.exit_code, 0) << d.err;
  EXPECT_TRUE(fs::exists(tmp / "d.png"));
  const std::size_t at = d.out.find("tone-mapped mean ");
  ASSERT_NE(at, std::string::npos) << d.out;
  const double psnr_tm = std::stod(d.out.substr(at + 17));
  EXPECT_GT(psnr_tm, 30.0) << d.out;
  EXPECT_LT(psnr_tm, 100.0) << d.out;  // the model is lossy: not identical
  const Image env = render_ok(kScenes / "mesh-env.json", tmp / "e.exr", "--spp 2", &log);
  EXPECT_EQ(env.width, 480);
  EXPECT_NE(log.find("environment map"), std::string::npos) << log;
}

TEST(RenderCli, SceneErrorsNameTheJsonPath) {
  TempDir tmp;
  struct Case {
    std::string scene, message;
  };
  const std::string head =
      R"({"camera": {"type": "orthographic", "position": [0,0,5], "look_at": [0,0,0], "height": 2},
    "materials": {"m": {"type": "sample", "name": "plastic"}},)";
  const std::string light =
      R"("lights": [{"type": "directional", "to_light": [0,0,1], "irradiance": 1}]})";
  const std::vector<Case> cases = {
      {head +
           R"("objects": [{"type": "sphere", "center": [0,0,0], "radius": -1, "material": "m"}],)" +
           light,
       "scene.objects[0].radius: expected a positive number"},
      {head +
           R"("objects": [{"type": "sphere", "center": [0,0,0], "radius": 1, "material": "m", "colour": 1}],)" +
           light,
       "scene.objects[0].colour: unknown key"},
      {head + R"("objects": [{"type": "cone", "material": "m"}],)" + light,
       "scene.objects[0].type: unknown object type 'cone'"},
      {head + R"("objects": [{"type": "mesh", "file": "nope.drc", "material": "m"}],)" + light,
       "scene.objects[0].file: no such file"},
      {head + R"("objects": [{"type": "sphere", "center": [0,0], "radius": 1, "material": "m"}],)" +
           light,
       "scene.objects[0].center: expected [x, y, z]"},
      {head +
           R"("objects": [{"type": "sphere", "center": [0,0,0], "radius": 1, "material": "x"}],)" +
           light,
       "scene.objects[0].material: no material named 'x'"},
      {head + R"("objects": [], "lights": [{"type": "spot"}]})",
       "scene.lights[0].type: unknown light type"},
      {head + R"("objects": [], "lights": [{"type": "environment", "file": "sky.exr"}]})",
       "scene.lights[0].file: no such file"},
      {R"({"camera": {"type": "fisheye", "position": [0,0,5], "look_at": [0,0,0]}, "objects": [], )" +
           light,
       "scene.camera.type: expected perspective or orthographic"},
      {"{\"camera\": ", "not valid JSON"},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const fs::path p = tmp / ("bad" + std::to_string(i) + ".json");
    write(p, cases[i].scene);
    const auto r = run_cli("render " + q(p) + " -o " + q(tmp / "x.exr"));
    EXPECT_EQ(r.exit_code, 1) << i;
    EXPECT_NE(r.err.find(cases[i].message), std::string::npos) << i << ": " << r.err;
    EXPECT_NE(r.err.find(p.filename().string()), std::string::npos) << i << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;  // one line
  }
  const auto missing = run_cli("render " + q(tmp / "none.json") + " -o " + q(tmp / "x.exr"));
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("none.json: no such file"), std::string::npos) << missing.err;
  const auto builtin = run_cli("render --builtin nope -o " + q(tmp / "x.exr"));
  EXPECT_EQ(builtin.exit_code, 1);
  EXPECT_NE(builtin.err.find("unknown built-in scene 'nope'"), std::string::npos) << builtin.err;
}

TEST(ImgdiffCli, ReportsPsnrAndRejectsSizeMismatch) {
  TempDir tmp;
  Image a(8, 4), b(8, 4), c(4, 4);
  for (std::size_t i = 0; i < a.data.size(); ++i) {
    a.data[i] = float(i % 7) / 7.0f;
    b.data[i] = a.data[i];
  }
  b.at(2, 1, 0) += 0.5f;
  ASSERT_TRUE(write_exr(tmp / "a.exr", a).ok());
  ASSERT_TRUE(write_exr(tmp / "b.exr", b).ok());
  ASSERT_TRUE(write_exr(tmp / "c.exr", c).ok());
  const auto same = run_cli("imgdiff " + q(tmp / "a.exr") + " " + q(tmp / "a.exr"));
  ASSERT_EQ(same.exit_code, 0) << same.err;
  EXPECT_NE(same.out.find("mean 100.00 dB"), std::string::npos) << same.out;
  const auto r =
      run_cli("imgdiff " + q(tmp / "a.exr") + " " + q(tmp / "b.exr") + " -o " + q(tmp / "d.png"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // Channel R: one pixel off by 0.5 among 32, peak 6/7: 10 log10((6/7)^2 / (0.25 / 32)).
  const double expected_r = 10 * std::log10((6.0 / 7) * (6.0 / 7) / (0.25 / 32));
  char buf[32];
  std::snprintf(buf, sizeof buf, "PSNR R %.2f dB", expected_r);
  EXPECT_NE(r.out.find(buf), std::string::npos) << r.out << " expected " << buf;
  EXPECT_NE(r.out.find("G 100.00 dB"), std::string::npos) << r.out;
  auto diff = read_png(tmp / "d.png");
  ASSERT_TRUE(diff.ok());
  EXPECT_EQ(diff->width, 8);
  // The differing pixel is yellow (the top of viridis), the others dark purple.
  EXPECT_GT(diff->at(2, 1, 0), 0.9f);
  EXPECT_LT(diff->at(0, 0, 0), 0.4f);
  const auto bad = run_cli("imgdiff " + q(tmp / "a.exr") + " " + q(tmp / "c.exr"));
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("sizes differ"), std::string::npos) << bad.err;
  EXPECT_NE(bad.err.find("8x4"), std::string::npos) << bad.err;
  const auto missing = run_cli("imgdiff " + q(tmp / "a.exr") + " " + q(tmp / "zz.exr"));
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("zz.exr"), std::string::npos) << missing.err;
}

}  // namespace
}  // namespace cbrdf
