// SPDX-License-Identifier: MIT
// A render scene as `cbrdf render` reads it from JSON (world space, y up, right-handed).
//
// {
//   "image":  {"width": 512, "height": 512, "spp": 16},             (spp: Monte Carlo only)
//   "camera": {"type": "perspective" | "orthographic", "position": [x,y,z], "look_at": [x,y,z],
//              "up": [0,1,0], "fov_deg": 40 (perspective, vertical), "height": 2.5 (orthographic,
//              the view's vertical extent in world units)},
//   "materials": {"NAME": {"type": "merl", "file": "a.binary", "lookup": "nearest" | "linear"}
//                       | {"type": "cbrdf", "file": "a.cbrdf"}
//                       | {"type": "sample", "name": "near-mirror"}              (cbrdf sample
//                       --list) | {"type": "analytic", "lobes": [{"kind": "lambertian", "rgb":
//                       [..]},
//                            {"kind": "ggx" | "ward", "rgb": [..], "alpha": 0.1},
//                            {"kind": "ashikhmin-shirley", "rgb": [..], "exponent": 300}]}},
//   "objects": [{"type": "sphere", "center": [..], "radius": 1, "material": "NAME"},
//               {"type": "plane", "point": [..], "normal": [..], "material": "NAME"},
//               {"type": "mesh", "file": "a.drc" | "a.obj" | "a.ply", "material": "NAME",
//                "scale": 1, "translate": [0,0,0]}],
//   "lights": [{"type": "point", "position": [..], "intensity": [r,g,b] (W/sr)},
//              {"type": "directional", "to_light": [..], "irradiance": [r,g,b] (at normal
//              incidence)},
//              {"type": "rect", "corner": [..], "edge1": [..], "edge2": [..], "radiance": [..]}
//                (emits on the side of edge1 x edge2),
//              {"type": "environment", "file": "sky.exr", "scale": [..]} or
//              {"type": "environment", "radiance": [..]} (uniform)],
//   "integrator": {"max_bounces": 0}   (indirect bounces after the first hit; 0 = direct only)
// }
// Colours are a number (grey) or [r, g, b]. Relative file names are relative to the scene file.
// Environment maps are lat-long: pixel column u = (atan2(d.x, -d.z) + pi) / (2 pi) * width, row
// v = acos(d.y) / pi * height (row 0 looks up, +y).
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "cbrdf/analytic.h"
#include "cbrdf/image.h"
#include "cbrdf/status.h"
#include "render/mesh.h"
#include "render/vec.h"

namespace cbrdf::render {

struct Camera {
  bool orthographic = false;
  Vec3 position{0, 0, 5}, look_at{0, 0, 0}, up{0, 1, 0};
  double fov_deg = 40;
  double height = 2.5;
};

enum class MaterialType { kMerl, kCbrdf, kSample, kAnalytic };

struct MaterialDesc {
  std::string name;
  MaterialType type = MaterialType::kAnalytic;
  std::filesystem::path file;  // merl, cbrdf
  bool linear_lookup = false;  // merl: "linear" = trilinear (render/table_lookup.h)
  std::string sample_name;     // sample
  std::vector<Lobe> lobes;     // analytic
};

struct Sphere {
  Vec3 center;
  double radius = 1;
  int material = 0;
};
struct Plane {
  Vec3 point, normal{0, 1, 0};
  int material = 0;
};
struct MeshObject {
  std::shared_ptr<const TriangleMesh> mesh;  // world space, with its BVH
  int material = 0;
};

struct PointLight {
  Vec3 position;
  Rgb intensity{};
};
struct DirectionalLight {
  Vec3 to_light{0, 1, 0};  // unit
  Rgb irradiance{};
};
struct RectLight {
  Vec3 corner, edge1, edge2;
  Rgb radiance{};
};
struct EnvironmentLight {
  bool present = false;
  bool uniform = true;    // no map: radiance everywhere
  Rgb radiance{1, 1, 1};  // uniform radiance, or the map's scale
  Image map;
  std::filesystem::path file;
};

struct Scene {
  int width = 256, height = 256, spp = 16;
  int max_bounces = 0;
  Camera camera;
  std::vector<MaterialDesc> materials;
  std::vector<Sphere> spheres;
  std::vector<Plane> planes;
  std::vector<MeshObject> meshes;
  std::vector<PointLight> points;
  std::vector<DirectionalLight> directionals;
  std::vector<RectLight> rects;
  EnvironmentLight environment;
};

// Reads and validates a scene. Errors name the file and the JSON path: "s.json: objects[2].radius:
// expected a positive number, got -1".
Expected<Scene> load_scene(const std::filesystem::path& path);

}  // namespace cbrdf::render
