// SPDX-License-Identifier: MIT
// load_scene: JSON -> Scene, every problem reported with its JSON path.
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>

#include "cbrdf/image_io.h"
#include "render/scene.h"

namespace cbrdf::render {
namespace {

using nlohmann::json;

// Thrown inside this file only and turned into a Status by load_scene.
struct SceneError {
  ErrorCode code;
  std::string message;
};

[[noreturn]] void fail(const std::string& path, const std::string& what,
                       ErrorCode code = ErrorCode::kInvalidArgument) {
  throw SceneError{code, path + ": " + what};
}

std::string shown(const json& j) {
  std::string s = j.dump();
  return s.size() > 40 ? s.substr(0, 37) + "..." : s;
}

// A JSON object with its path; rejects keys it was not asked about.
class Obj {
 public:
  Obj(const json& j, std::string path, std::set<std::string> allowed)
      : j_(j), path_(std::move(path)) {
    if (!j.is_object()) fail(path_, "expected an object, got " + shown(j));
    for (const auto& [key, value] : j.items()) {
      if (!allowed.count(key)) {
        std::string list;
        for (const std::string& a : allowed) list += (list.empty() ? "" : ", ") + a;
        fail(at(key), "unknown key (valid: " + list + ")");
      }
    }
  }
  std::string at(const std::string& key) const { return path_ + "." + key; }
  const std::string& path() const { return path_; }
  bool has(const std::string& key) const { return j_.contains(key); }
  const json& get(const std::string& key) const {
    if (!j_.contains(key)) fail(at(key), "missing");
    return j_.at(key);
  }

  double number(const std::string& key, double fallback, bool positive = false) const {
    if (!has(key)) return fallback;
    return number(key, positive);
  }
  double number(const std::string& key, bool positive = false) const {
    const json& v = get(key);
    if (!v.is_number()) fail(at(key), "expected a number, got " + shown(v));
    const double d = v.get<double>();
    if (!std::isfinite(d) || (positive && !(d > 0))) {
      fail(at(key), std::string("expected a ") + (positive ? "positive " : "finite ") +
                        "number, got " + shown(v));
    }
    return d;
  }
  int integer(const std::string& key, int fallback, int lo, int hi) const {
    if (!has(key)) return fallback;
    const json& v = get(key);
    if (!v.is_number_integer() || v.get<long long>() < lo || v.get<long long>() > hi) {
      fail(at(key), "expected an integer from " + std::to_string(lo) + " to " + std::to_string(hi) +
                        ", got " + shown(v));
    }
    return int(v.get<long long>());
  }
  std::string string(const std::string& key) const {
    const json& v = get(key);
    if (!v.is_string()) fail(at(key), "expected a string, got " + shown(v));
    return v.get<std::string>();
  }
  Vec3 vec3(const std::string& key) const {
    const json& v = get(key);
    if (!v.is_array() || v.size() != 3 || !v[0].is_number() || !v[1].is_number() ||
        !v[2].is_number()) {
      fail(at(key), "expected [x, y, z], got " + shown(v));
    }
    const Vec3 r{v[0].get<double>(), v[1].get<double>(), v[2].get<double>()};
    if (!std::isfinite(r.x + r.y + r.z)) fail(at(key), "not finite");
    return r;
  }
  Vec3 vec3(const std::string& key, const Vec3& fallback) const {
    return has(key) ? vec3(key) : fallback;
  }
  Vec3 direction(const std::string& key) const {
    const Vec3 v = vec3(key);
    if (!(length(v) > 0)) fail(at(key), "expected a non-zero direction");
    return normalize(v);
  }
  // A colour: one non-negative number (grey) or [r, g, b].
  Rgb rgb(const std::string& key) const {
    const json& v = get(key);
    Rgb c{};
    if (v.is_number()) {
      c = {v.get<double>(), v.get<double>(), v.get<double>()};
    } else if (v.is_array() && v.size() == 3 && v[0].is_number() && v[1].is_number() &&
               v[2].is_number()) {
      c = {v[0].get<double>(), v[1].get<double>(), v[2].get<double>()};
    } else {
      fail(at(key), "expected a colour (a number or [r, g, b]), got " + shown(v));
    }
    for (double x : c) {
      if (!std::isfinite(x) || x < 0) fail(at(key), "colour values must be finite and >= 0");
    }
    return c;
  }
  Rgb rgb(const std::string& key, const Rgb& fallback) const {
    return has(key) ? rgb(key) : fallback;
  }

 private:
  const json& j_;
  std::string path_;
};

std::filesystem::path resolve(const std::filesystem::path& dir, const Obj& o,
                              const std::string& key) {
  const std::filesystem::path p = o.string(key);
  const std::filesystem::path full = p.is_absolute() ? p : dir / p;
  if (!std::filesystem::exists(full)) {
    fail(o.at(key), "no such file: " + full.string(), ErrorCode::kNotFound);
  }
  return full;
}

Lobe parse_lobe(const Obj& o) {
  const std::string kind = o.string("kind");
  const Rgb c = o.rgb("rgb");
  if (kind == "lambertian") return lambertian(c);
  if (kind == "ggx") return ggx(c, o.number("alpha", true));
  if (kind == "ward") return ward(c, o.number("alpha", true));
  if (kind == "ashikhmin-shirley") return ashikhmin_shirley(c, o.number("exponent", true));
  fail(o.at("kind"),
       "unknown lobe kind '" + kind + "' (valid: lambertian, ggx, ward, ashikhmin-shirley)");
}

MaterialDesc parse_material(const std::string& name, const json& j, const std::string& path,
                            const std::filesystem::path& dir) {
  MaterialDesc m;
  m.name = name;
  if (!j.is_object() || !j.contains("type") || !j["type"].is_string()) {
    fail(path + ".type", "missing: a material needs \"type\": merl, cbrdf, sample or analytic");
  }
  const std::string type = j["type"].get<std::string>();
  if (type == "merl") {
    const Obj o(j, path, {"type", "file", "lookup"});
    m.type = MaterialType::kMerl;
    m.file = resolve(dir, o, "file");
    if (o.has("lookup")) {
      const std::string l = o.string("lookup");
      if (l != "nearest" && l != "linear") fail(o.at("lookup"), "expected nearest or linear");
      m.linear_lookup = l == "linear";
    }
  } else if (type == "cbrdf") {
    const Obj o(j, path, {"type", "file"});
    m.type = MaterialType::kCbrdf;
    m.file = resolve(dir, o, "file");
  } else if (type == "sample") {
    const Obj o(j, path, {"type", "name"});
    m.type = MaterialType::kSample;
    m.sample_name = o.string("name");
  } else if (type == "analytic") {
    const Obj o(j, path, {"type", "lobes"});
    m.type = MaterialType::kAnalytic;
    const json& lobes = o.get("lobes");
    if (!lobes.is_array() || lobes.empty()) fail(o.at("lobes"), "expected a non-empty array");
    for (std::size_t i = 0; i < lobes.size(); ++i) {
      const std::string lp = o.at("lobes") + "[" + std::to_string(i) + "]";
      m.lobes.push_back(parse_lobe(Obj(lobes[i], lp, {"kind", "rgb", "alpha", "exponent"})));
    }
    if (Status s = AnalyticBrdf{m.lobes}.validate(); !s.ok()) fail(o.at("lobes"), s.message());
  } else {
    fail(path + ".type",
         "unknown material type '" + type + "' (valid: merl, cbrdf, sample, analytic)");
  }
  return m;
}

void parse_light(const json& j, const std::string& path, const std::filesystem::path& dir,
                 Scene* scene) {
  if (!j.is_object() || !j.contains("type") || !j["type"].is_string()) {
    fail(path + ".type",
         "missing: a light needs \"type\": point, directional, rect or environment");
  }
  const std::string type = j["type"].get<std::string>();
  if (type == "point") {
    const Obj o(j, path, {"type", "position", "intensity"});
    scene->points.push_back({o.vec3("position"), o.rgb("intensity")});
  } else if (type == "directional") {
    const Obj o(j, path, {"type", "to_light", "irradiance"});
    scene->directionals.push_back({o.direction("to_light"), o.rgb("irradiance")});
  } else if (type == "rect") {
    const Obj o(j, path, {"type", "corner", "edge1", "edge2", "radiance"});
    RectLight r{o.vec3("corner"), o.vec3("edge1"), o.vec3("edge2"), o.rgb("radiance")};
    if (!(length(cross(r.edge1, r.edge2)) > 0)) fail(path, "edge1 and edge2 span no area");
    scene->rects.push_back(r);
  } else if (type == "environment") {
    const Obj o(j, path, {"type", "file", "scale", "radiance"});
    if (scene->environment.present) fail(path, "a scene has at most one environment light");
    EnvironmentLight& e = scene->environment;
    e.present = true;
    if (o.has("file")) {
      if (o.has("radiance")) fail(o.at("radiance"), "give either file (with scale) or radiance");
      e.file = resolve(dir, o, "file");
      auto img = read_exr(e.file);
      if (!img.ok()) fail(o.at("file"), img.status().message(), img.status().code());
      if (img->width < 2 || img->height < 1) fail(o.at("file"), "the map is too small");
      for (float v : img->data) {
        if (!std::isfinite(v) || v < 0)
          fail(o.at("file"), "the map holds negative or non-finite values");
      }
      e.map = std::move(*img);
      e.uniform = false;
      e.radiance = o.rgb("scale", {1, 1, 1});
    } else {
      if (o.has("scale")) fail(o.at("scale"), "scale applies to a map file only");
      e.radiance = o.rgb("radiance", {1, 1, 1});
    }
  } else {
    fail(path + ".type",
         "unknown light type '" + type + "' (valid: point, directional, rect, environment)");
  }
}

void parse_object(const json& j, const std::string& path, const std::filesystem::path& dir,
                  const std::map<std::string, int>& materials, Scene* scene) {
  if (!j.is_object() || !j.contains("type") || !j["type"].is_string()) {
    fail(path + ".type", "missing: an object needs \"type\": sphere, plane or mesh");
  }
  const std::string type = j["type"].get<std::string>();
  auto material = [&](const Obj& o) {
    const std::string name = o.string("material");
    auto it = materials.find(name);
    if (it == materials.end()) fail(o.at("material"), "no material named '" + name + "'");
    return it->second;
  };
  if (type == "sphere") {
    const Obj o(j, path, {"type", "center", "radius", "material"});
    scene->spheres.push_back({o.vec3("center"), o.number("radius", true), material(o)});
  } else if (type == "plane") {
    const Obj o(j, path, {"type", "point", "normal", "material"});
    scene->planes.push_back({o.vec3("point"), o.direction("normal"), material(o)});
  } else if (type == "mesh") {
    const Obj o(j, path, {"type", "file", "material", "scale", "translate"});
    const std::filesystem::path file = resolve(dir, o, "file");
    auto mesh = load_mesh(file);
    if (!mesh.ok()) fail(o.at("file"), mesh.status().message(), mesh.status().code());
    const double scale = o.number("scale", 1.0);
    if (scale == 0) fail(o.at("scale"), "must not be 0");
    mesh->finalize(scale, o.vec3("translate", {0, 0, 0}));
    scene->meshes.push_back({std::make_shared<const TriangleMesh>(std::move(*mesh)), material(o)});
  } else {
    fail(path + ".type", "unknown object type '" + type + "' (valid: sphere, plane, mesh)");
  }
}

Scene parse_scene(const json& root, const std::filesystem::path& dir) {
  Scene scene;
  const Obj top(root, "scene", {"image", "camera", "materials", "objects", "lights", "integrator"});
  if (top.has("image")) {
    const Obj o(top.get("image"), top.at("image"), {"width", "height", "spp"});
    scene.width = o.integer("width", scene.width, 1, 8192);
    scene.height = o.integer("height", scene.height, 1, 8192);
    scene.spp = o.integer("spp", scene.spp, 1, 1 << 20);
  }
  {
    const Obj o(top.get("camera"), top.at("camera"),
                {"type", "position", "look_at", "up", "fov_deg", "height"});
    Camera& c = scene.camera;
    const std::string type = o.string("type");
    if (type != "perspective" && type != "orthographic") {
      fail(o.at("type"), "expected perspective or orthographic, got '" + type + "'");
    }
    c.orthographic = type == "orthographic";
    c.position = o.vec3("position");
    c.look_at = o.vec3("look_at");
    c.up = o.vec3("up", {0, 1, 0});
    if (!(length(c.look_at - c.position) > 0)) fail(o.at("look_at"), "equals the position");
    if (!(length(cross(c.look_at - c.position, c.up)) > 0))
      fail(o.at("up"), "parallel to the view");
    if (c.orthographic) {
      if (o.has("fov_deg")) fail(o.at("fov_deg"), "applies to a perspective camera only");
      c.height = o.number("height", true);
    } else {
      if (o.has("height")) fail(o.at("height"), "applies to an orthographic camera only");
      c.fov_deg = o.number("fov_deg", 40.0, true);
      if (c.fov_deg >= 180) fail(o.at("fov_deg"), "must be below 180");
    }
  }
  std::map<std::string, int> names;
  if (top.has("materials")) {
    const json& mats = top.get("materials");
    if (!mats.is_object()) fail(top.at("materials"), "expected an object of named materials");
    for (const auto& [name, value] : mats.items()) {
      names[name] = int(scene.materials.size());
      scene.materials.push_back(parse_material(name, value, top.at("materials") + "." + name, dir));
    }
  }
  const json& objects = top.get("objects");
  if (!objects.is_array()) fail(top.at("objects"), "expected an array");
  for (std::size_t i = 0; i < objects.size(); ++i) {
    parse_object(objects[i], top.at("objects") + "[" + std::to_string(i) + "]", dir, names, &scene);
  }
  const json& lights = top.get("lights");
  if (!lights.is_array() || lights.empty()) fail(top.at("lights"), "expected a non-empty array");
  for (std::size_t i = 0; i < lights.size(); ++i) {
    parse_light(lights[i], top.at("lights") + "[" + std::to_string(i) + "]", dir, &scene);
  }
  if (top.has("integrator")) {
    const Obj o(top.get("integrator"), top.at("integrator"), {"max_bounces"});
    scene.max_bounces = o.integer("max_bounces", 0, 0, 64);
  }
  return scene;
}

}  // namespace

Expected<Scene> load_scene(const std::filesystem::path& path) {
  const std::string name = path.string();
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return error(std::filesystem::exists(path) ? ErrorCode::kIo : ErrorCode::kNotFound,
                 name + ": " + (std::filesystem::exists(path) ? "cannot open" : "no such file"));
  }
  std::stringstream ss;
  ss << in.rdbuf();
  json root = json::parse(ss.str(), nullptr, /*allow_exceptions=*/false);
  if (root.is_discarded()) {
    // Parse again with exceptions only to get nlohmann's position message.
    try {
      const json again = json::parse(ss.str());
      if (!again.is_discarded()) return error(ErrorCode::kCorrupt, name + ": not valid JSON");
    } catch (const json::parse_error& e) {
      return error(ErrorCode::kCorrupt, name + ": not valid JSON: " + e.what());
    }
    return error(ErrorCode::kCorrupt, name + ": not valid JSON");
  }
  try {
    return parse_scene(root, path.parent_path());
  } catch (const SceneError& e) {
    return error(e.code, name + ": " + e.message);
  }
}

}  // namespace cbrdf::render
