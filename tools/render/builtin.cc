// SPDX-License-Identifier: MIT
// Built-in scenes: written out (scene JSON plus generated assets) so that they render like any
// scene file. tests/data/scenes/ holds their exported copies.
#include "render/builtin.h"

#include <cmath>
#include <fstream>
#include <map>
#include <numbers>

#include "cbrdf/encoder.h"
#include "cbrdf/file_io.h"
#include "cbrdf/image_io.h"
#include "cbrdf/samples.h"
#include "render/mesh.h"

namespace cbrdf::render {
namespace {

constexpr double kPi = std::numbers::pi;

// The paper's Figure 4 columns, with built-in samples standing in for the measured materials
// (dark-blue-paint, blue-metallic-paint, fruitwood, nickel, yellow plastic, chrome-steel).
constexpr const char* kFigure4Samples[] = {"ward",      "ggx-rough", "ashikhmin-shirley",
                                           "ggx-sharp", "plastic",   "near-mirror"};

// The figure-4 scene's layout as figure4_scene's JSON writes it (kept in step by render_test).
constexpr int kFigure4Width = 1320, kFigure4Height = 240;
constexpr double kFigure4ViewHeight = 2.4, kFigure4Spacing = 2.2, kFigure4Irradiance = 3.0;
constexpr Vec3 kFigure4ToLight{0.5, 0.45, 0.74};

Status write_text(const std::filesystem::path& path, const std::string& text) {
  return write_file_atomic(
      path, std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(text.data()),
                                          text.size()));
}

// Fits a built-in sample and writes it as .cbrdf: 12 bits in the 1.2 coding with full metadata,
// the files the built-in scenes have always rendered.
Status write_sample_cbrdf(const std::string& sample, const std::filesystem::path& path) {
  CBRDF_ASSIGN_OR_RETURN(auto table, make_sample(sample));
  EncoderSettings settings;
  settings.auto_bits.enabled = false;
  settings.container.format = ContainerSettings::Format::kV12;
  settings.container.metadata = ContainerSettings::Metadata::kFull;
  settings.container.source_name = "sample:" + sample;
  auto encoded = encode_table(table, settings);
  if (!encoded.ok()) return encoded.status().with_context(path.string());
  return write_file_atomic(path, encoded->bytes);
}

std::string figure4_scene(bool model) {
  std::string materials, objects;
  const int n = int(std::size(kFigure4Samples));
  for (int i = 0; i < n; ++i) {
    const std::string s = kFigure4Samples[i];
    if (i > 0) {
      materials += ",\n";
      objects += ",\n";
    }
    materials += "    \"" + s + "\": " +
                 (model ? "{\"type\": \"cbrdf\", \"file\": \"" + s + ".cbrdf\"}"
                        : "{\"type\": \"sample\", \"name\": \"" + s + "\"}");
    const double x = (i - (n - 1) / 2.0) * 2.2;
    objects += "    {\"type\": \"sphere\", \"center\": [" + std::to_string(x) +
               ", 0, 0], \"radius\": 1, \"material\": \"" + s + "\"}";
  }
  return "{\n"
         "  \"image\": {\"width\": 1320, \"height\": 240},\n"
         "  \"camera\": {\"type\": \"orthographic\", \"position\": [0, 0, 10], \"look_at\": [0, 0, "
         "0], \"height\": 2.4},\n"
         "  \"materials\": {\n" +
         materials +
         "\n  },\n"
         "  \"objects\": [\n" +
         objects +
         "\n  ],\n"
         "  \"lights\": [{\"type\": \"directional\", \"to_light\": [0.5, 0.45, 0.74], "
         "\"irradiance\": 3.0}]\n"
         "}\n";
}

// Loop subdivision without smoothing: each triangle split in four, new vertices pushed to the
// unit sphere. 3 levels: 642 vertices, 1280 triangles.
TriangleMesh icosphere(int levels) {
  TriangleMesh m;
  const double t = (1 + std::sqrt(5.0)) / 2;
  for (const Vec3& v : {Vec3{-1, t, 0}, Vec3{1, t, 0}, Vec3{-1, -t, 0}, Vec3{1, -t, 0},
                        Vec3{0, -1, t}, Vec3{0, 1, t}, Vec3{0, -1, -t}, Vec3{0, 1, -t},
                        Vec3{t, 0, -1}, Vec3{t, 0, 1}, Vec3{-t, 0, -1}, Vec3{-t, 0, 1}}) {
    m.positions.push_back(normalize(v));
  }
  m.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                 {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                 {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                 {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
    auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      m.positions.push_back(normalize(m.positions[a] + m.positions[b]));
      const auto i = std::uint32_t(m.positions.size() - 1);
      mid[key] = i;
      return i;
    };
    std::vector<std::array<std::uint32_t, 3>> next;
    for (const auto& tri : m.triangles) {
      const std::uint32_t a = midpoint(tri[0], tri[1]), b = midpoint(tri[1], tri[2]),
                          c = midpoint(tri[2], tri[0]);
      next.push_back({tri[0], a, c});
      next.push_back({tri[1], b, a});
      next.push_back({tri[2], c, b});
      next.push_back({a, b, c});
    }
    m.triangles = std::move(next);
  }
  m.normals = m.positions;
  return m;
}

// A small procedural sky: blue gradient above, warm grey ground below, a sun disc at 35 deg
// elevation. Lat-long as scene.h defines it.
Image sky_map(int width, int height) {
  Image img(width, height);
  const Vec3 sun = normalize(Vec3{0.6, 0.57, 0.55});
  for (int y = 0; y < height; ++y) {
    const double theta = (y + 0.5) / height * kPi;
    for (int x = 0; x < width; ++x) {
      const double phi = (x + 0.5) / width * 2 * kPi - kPi;
      const Vec3 d{std::sin(theta) * std::sin(phi), std::cos(theta),
                   -std::sin(theta) * std::cos(phi)};
      Rgb c = d.y > 0 ? Rgb{0.35 + 0.4 * (1 - d.y), 0.55 + 0.3 * (1 - d.y), 1.0}
                      : Rgb{0.25, 0.22, 0.18};
      if (dot(d, sun) > std::cos(4.0 * kPi / 180)) c = {300.0, 280.0, 250.0};
      for (int k = 0; k < 3; ++k) img.at(x, y, k) = float(c[k]);
    }
  }
  return img;
}

const char* kMeshEnvScene = R"({
  "image": {"width": 480, "height": 270, "spp": 32},
  "camera": {"type": "perspective", "position": [0, 1.3, 4.6], "look_at": [0, 0.6, 0], "fov_deg": 38},
  "materials": {
    "gold": {"type": "cbrdf", "file": "gold.cbrdf"},
    "plastic": {"type": "cbrdf", "file": "plastic.cbrdf"},
    "floor": {"type": "analytic", "lobes": [{"kind": "lambertian", "rgb": [0.5, 0.5, 0.5]}]}
  },
  "objects": [
    {"type": "mesh", "file": "icosphere.drc", "material": "gold", "scale": 0.75, "translate": [-0.85, 0.75, 0]},
    {"type": "sphere", "center": [0.85, 0.75, 0], "radius": 0.75, "material": "plastic"},
    {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "material": "floor"}
  ],
  "lights": [{"type": "environment", "file": "sky.exr"}],
  "integrator": {"max_bounces": 0}
}
)";

}  // namespace

Scene figure4_one_material(const MaterialDesc& material, double scale) {
  Scene s;
  s.width = std::max(1, int(std::lround(kFigure4Width * scale)));
  s.height = std::max(1, int(std::lround(kFigure4Height * scale)));
  s.camera.orthographic = true;
  s.camera.position = {0, 0, 10};
  s.camera.look_at = {0, 0, 0};
  s.camera.height = kFigure4ViewHeight;
  s.materials = {material};
  const int n = int(std::size(kFigure4Samples));
  for (int i = 0; i < n; ++i)
    s.spheres.push_back({{(i - (n - 1) / 2.0) * kFigure4Spacing, 0, 0}, 1, 0});
  s.directionals.push_back(
      {normalize(kFigure4ToLight), {kFigure4Irradiance, kFigure4Irradiance, kFigure4Irradiance}});
  return s;
}

std::vector<BuiltinScene> builtin_scenes() {
  return {
      {"figure4", "figure4.json",
       "the paper's Figure 4 layout: six model spheres in a row under a directional light"},
      {"figure4-reference", "figure4-reference.json",
       "Figure 4's reference row: the analytic materials the models were fitted to"},
      {"mesh-env", "mesh-env.json",
       "a Draco icosphere and a sphere (copula models) on a floor under a sky environment map"}};
}

Expected<std::filesystem::path> export_builtin(const std::string& name,
                                               const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return error(ErrorCode::kIo, dir.string() + ": cannot create: " + ec.message());
  if (name == "figure4" || name == "figure4-reference") {
    const bool model = name == "figure4";
    if (model) {
      for (const char* s : kFigure4Samples) {
        CBRDF_RETURN_IF_ERROR(write_sample_cbrdf(s, dir / (std::string(s) + ".cbrdf")));
      }
    }
    const std::filesystem::path scene = dir / (name + ".json");
    CBRDF_RETURN_IF_ERROR(write_text(scene, figure4_scene(model)));
    return scene;
  }
  if (name == "mesh-env") {
    CBRDF_RETURN_IF_ERROR(write_drc(dir / "icosphere.drc", icosphere(3)));
    CBRDF_RETURN_IF_ERROR(write_exr(dir / "sky.exr", sky_map(128, 64)));
    CBRDF_RETURN_IF_ERROR(write_sample_cbrdf("ggx-sharp", dir / "gold.cbrdf"));
    CBRDF_RETURN_IF_ERROR(write_sample_cbrdf("plastic", dir / "plastic.cbrdf"));
    const std::filesystem::path scene = dir / "mesh-env.json";
    CBRDF_RETURN_IF_ERROR(write_text(scene, kMeshEnvScene));
    return scene;
  }
  std::string names;
  for (const BuiltinScene& b : builtin_scenes()) names += (names.empty() ? "" : ", ") + b.name;
  return error(ErrorCode::kInvalidArgument,
               "unknown built-in scene '" + name + "' (valid: " + names + ")");
}

}  // namespace cbrdf::render
