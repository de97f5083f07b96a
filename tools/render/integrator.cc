// SPDX-License-Identifier: MIT
#include "render/integrator.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>

#include "cbrdf/parallel.h"
#include "render/lights.h"

namespace cbrdf::render {
namespace {

// The ray parameters t0 <= t1 where the ray (unit direction) meets the sphere; false if it misses.
bool sphere_roots(const Sphere& sp, const Ray& ray, double* t0, double* t1) {
  const Vec3 oc = ray.origin - sp.center;
  const double b = dot(oc, ray.dir), c = dot(oc, oc) - sp.radius * sp.radius;
  const double disc = b * b - c;
  if (disc < 0) return false;
  const double sq = std::sqrt(disc);
  *t0 = -b - sq;
  *t1 = -b + sq;
  return true;
}

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = std::numbers::pi;

// PCG32 (O'Neill): small, fast and good enough for pixel sampling.
class Rng {
 public:
  Rng(std::uint64_t seed, std::uint64_t stream) : inc_((stream << 1u) | 1u) {
    next();
    state_ += seed;
    next();
  }
  std::uint32_t next() {
    const std::uint64_t old = state_;
    state_ = old * 6364136223846793005ULL + inc_;
    const auto xorshifted = std::uint32_t(((old >> 18u) ^ old) >> 27u);
    const auto rot = std::uint32_t(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31u));
  }
  double uniform() { return next() * 0x1p-32; }  // [0, 1)

 private:
  std::uint64_t state_ = 0, inc_;
};

std::uint64_t mix(std::uint64_t x) {  // splitmix64 finalizer
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

double power_heuristic(double a, double b) {
  if (!(a > 0)) return 0;
  if (std::isinf(a)) return 1;
  return a * a / (a * a + b * b);
}

struct Hit {
  double t = kInf;
  Vec3 p, ng, ns;  // geometric and shading normals, not yet facing the ray
  int material = -1;
  int light = -1;  // a rect light's index when the ray hit an emitter
};

class World {
 public:
  explicit World(const Scene& s) : s_(s) {
    double extent = 1;
    for (const Sphere& sp : s.spheres) extent = std::max(extent, length(sp.center) + sp.radius);
    for (const MeshObject& m : s.meshes) {
      extent = std::max({extent, length(m.mesh->bounds_min()), length(m.mesh->bounds_max())});
    }
    eps_ = 1e-6 * extent;
  }
  double eps() const { return eps_; }

  bool intersect(const Ray& ray, Hit* hit) const {
    hit->t = kInf;
    for (const Sphere& sp : s_.spheres) {
      double t0 = 0, t1 = 0;
      if (!sphere_roots(sp, ray, &t0, &t1)) continue;
      const double t = t0 > 0 ? t0 : t1;
      if (t > 0 && t < hit->t) {
        hit->t = t;
        hit->p = ray.origin + ray.dir * t;
        hit->ng = hit->ns = (hit->p - sp.center) * (1 / sp.radius);
        hit->material = sp.material;
        hit->light = -1;
      }
    }
    for (const Plane& pl : s_.planes) {
      const double denom = dot(ray.dir, pl.normal);
      if (denom == 0) continue;
      const double t = dot(pl.point - ray.origin, pl.normal) / denom;
      if (t > 0 && t < hit->t) {
        hit->t = t;
        hit->p = ray.origin + ray.dir * t;
        hit->ng = hit->ns = pl.normal;
        hit->material = pl.material;
        hit->light = -1;
      }
    }
    for (const MeshObject& m : s_.meshes) {
      MeshHit mh;
      mh.t = hit->t;
      if (m.mesh->intersect(ray, 0.0, &mh)) {
        hit->t = mh.t;
        hit->p = ray.origin + ray.dir * mh.t;
        hit->ng = m.mesh->geometric_normal(mh.triangle);
        hit->ns = m.mesh->shading_normal(mh);
        hit->material = m.material;
        hit->light = -1;
      }
    }
    for (std::size_t i = 0; i < s_.rects.size(); ++i) {
      const double t = hit_rect(s_.rects[i], ray, 0.0, hit->t);
      if (t > 0) {
        hit->t = t;
        hit->p = ray.origin + ray.dir * t;
        hit->light = int(i);
      }
    }
    return std::isfinite(hit->t);
  }

  bool occluded(const Ray& ray, double t_max) const {
    for (const Sphere& sp : s_.spheres) {
      double t0 = 0, t1 = 0;
      if (!sphere_roots(sp, ray, &t0, &t1)) continue;
      if ((t0 > 0 && t0 < t_max) || (t1 > 0 && t1 < t_max)) return true;
    }
    for (const Plane& pl : s_.planes) {
      const double denom = dot(ray.dir, pl.normal);
      if (denom == 0) continue;
      const double t = dot(pl.point - ray.origin, pl.normal) / denom;
      if (t > 0 && t < t_max) return true;
    }
    for (const MeshObject& m : s_.meshes) {
      if (m.mesh->occluded(ray, 0.0, t_max)) return true;
    }
    for (const RectLight& r : s_.rects) {
      if (hit_rect(r, ray, 0.0, t_max) > 0) return true;
    }
    return false;
  }

 private:
  const Scene& s_;
  double eps_ = 1e-6;
};

struct CameraRays {
  Vec3 forward, right, up;
  double aspect = 1, tan_half = 0;
  const Camera* c = nullptr;
  int width = 1, height = 1;

  CameraRays(const Camera& cam, int w, int h) : c(&cam), width(w), height(h) {
    forward = normalize(cam.look_at - cam.position);
    right = normalize(cross(forward, cam.up));
    up = cross(right, forward);
    aspect = double(w) / h;
    tan_half = std::tan(cam.fov_deg * kPi / 360);
  }
  // (fx, fy) in pixel units: pixel (x, y) covers [x, x+1) x [y, y+1), row 0 at the top.
  Ray ray(double fx, double fy) const {
    const double sx = (fx / width * 2 - 1) * aspect, sy = 1 - fy / height * 2;
    if (c->orthographic) {
      const double half = c->height / 2;
      return {c->position + right * (sx * half) + up * (sy * half), forward};
    }
    return {c->position, normalize(forward + right * (sx * tan_half) + up * (sy * tan_half))};
  }
};

class Integrator {
 public:
  Integrator(const Scene& s, const std::vector<std::unique_ptr<Material>>& m, const RenderPlan& p)
      : s_(s),
        mats_(m),
        plan_(p),
        world_(s),
        env_(s.environment),
        cam_(s.camera, s.width, s.height) {}

  Rgb pixel(int x, int y) const {
    if (!plan_.monte_carlo) {
      Rng unused(0, 0);
      return trace(cam_.ray(x + 0.5, y + 0.5), unused);
    }
    Rng rng(mix(std::uint64_t(y) * std::uint64_t(s_.width) + std::uint64_t(x)), 0x5eed);
    Rgb sum{0, 0, 0};
    for (int i = 0; i < plan_.spp; ++i) {
      const double jx = rng.uniform(), jy = rng.uniform();
      sum += trace(cam_.ray(x + jx, y + jy), rng);
    }
    return sum * (1.0 / plan_.spp);
  }

 private:
  // How far a shadow ray from a surface point offset by eps may go toward a light point at dist:
  // stopping short of the light itself, which the occlusion test would otherwise find.
  double shadow_reach(double dist) const {
    return std::isinf(dist) ? dist : dist - 4 * world_.eps() - 1e-9 * dist;
  }

  // Light arriving along a delta light, or 0 when it is behind the surface or shadowed.
  Rgb delta_lights(const Vec3& p, const Vec3& ng, const Frame& frame, const Vec3& wo,
                   const Material& mat) const {
    Rgb out{0, 0, 0};
    auto add = [&](const Vec3& wi, double dist, const Rgb& e) {
      const Vec3 wl = frame.to_local(wi);
      if (!(wl.z > 0) || !(dot(ng, wi) > 0)) return;
      if (plan_.shadow_rays && world_.occluded({p + ng * world_.eps(), wi}, shadow_reach(dist))) {
        return;
      }
      double f[3];
      mat.eval(wl, wo, f);
      for (int c = 0; c < 3; ++c) out[c] += f[c] * wl.z * e[c];
    };
    for (const DirectionalLight& d : s_.directionals) add(d.to_light, kInf, d.irradiance);
    for (const PointLight& pl : s_.points) {
      const Vec3 d = pl.position - p;
      const double dist = length(d);
      if (!(dist > 0)) continue;
      add(d * (1 / dist), dist, pl.intensity * (1 / (dist * dist)));
    }
    return out;
  }

  // One light sample per rect light and for the environment, MIS-weighted against BRDF sampling.
  Rgb sampled_lights(const Vec3& p, const Vec3& ng, const Frame& frame, const Vec3& wo,
                     const Material& mat, Rng& rng) const {
    Rgb out{0, 0, 0};
    auto add = [&](const Vec3& wi, double dist, double pdf_light, const Rgb& le) {
      if (!(pdf_light > 0) || is_black(le)) return;
      const Vec3 wl = frame.to_local(wi);
      if (!(wl.z > 0) || !(dot(ng, wi) > 0)) return;
      double f[3];
      mat.eval(wl, wo, f);
      if (f[0] == 0 && f[1] == 0 && f[2] == 0) return;
      if (world_.occluded({p + ng * world_.eps(), wi}, shadow_reach(dist))) return;
      const double w = power_heuristic(pdf_light, mat.sampler().sample_pdf(wl, wo));
      for (int c = 0; c < 3; ++c) out[c] += f[c] * wl.z * le[c] * w / pdf_light;
    };
    for (const RectLight& r : s_.rects) {
      const double u1 = rng.uniform(), u2 = rng.uniform();
      const RectSample ls = sample_rect(r, p, u1, u2);
      add(ls.wi, ls.dist, ls.pdf, r.radiance);
    }
    if (env_.present()) {
      const double u1 = rng.uniform(), u2 = rng.uniform();
      double pdf = 0;
      const Vec3 wi = env_.sample(u1, u2, &pdf);
      add(wi, kInf, pdf, env_.radiance(wi));
    }
    return out;
  }

  Rgb trace(Ray ray, Rng& rng) const {
    Hit hit;
    if (!world_.intersect(ray, &hit)) return env_.radiance(ray.dir);
    if (hit.light >= 0) return rect_emission(s_.rects[std::size_t(hit.light)], ray.dir);
    const bool sample_brdf = plan_.monte_carlo && (!s_.rects.empty() || env_.present());
    Rgb radiance{0, 0, 0}, beta{1, 1, 1};
    for (int depth = 0;; ++depth) {
      const Material& mat = *mats_[std::size_t(hit.material)];
      const Vec3 wo_world = -ray.dir;
      Vec3 ng = hit.ng, ns = hit.ns;
      if (dot(ng, wo_world) < 0) {  // surfaces are two-sided
        ng = -ng;
        ns = -ns;
      }
      const Frame frame(ns);
      const Vec3 wo = frame.to_local(wo_world);
      if (!(wo.z > 0)) break;
      radiance += beta * delta_lights(hit.p, ng, frame, wo, mat);
      if (sample_brdf) radiance += beta * sampled_lights(hit.p, ng, frame, wo, mat, rng);
      if (!sample_brdf && depth >= plan_.max_bounces) break;
      const double u1 = rng.uniform(), u2 = rng.uniform();
      const BrdfSample bs = mat.sampler().sample(wo, u1, u2);
      if (!bs.valid) break;
      const Vec3 wi = frame.to_world(bs.wi);
      if (!(dot(ng, wi) > 0)) break;
      double f[3];
      mat.eval(bs.wi, wo, f);
      const Rgb weight{f[0] * bs.wi.z / bs.pdf, f[1] * bs.wi.z / bs.pdf, f[2] * bs.wi.z / bs.pdf};
      if (is_black(weight)) break;
      ray = {hit.p + ng * world_.eps(), wi};
      Hit next;
      if (!world_.intersect(ray, &next)) {
        if (sample_brdf && env_.present()) {
          const double w = power_heuristic(bs.pdf, env_.pdf(wi));
          radiance += beta * weight * env_.radiance(wi) * w;
        }
        break;
      }
      if (next.light >= 0) {
        if (sample_brdf) {
          const RectLight& r = s_.rects[std::size_t(next.light)];
          const double w = power_heuristic(bs.pdf, rect_pdf(r, wi, next.t));
          radiance += beta * weight * rect_emission(r, wi) * w;
        }
        break;
      }
      if (depth >= plan_.max_bounces) break;
      beta = beta * weight;
      hit = next;
    }
    return radiance;
  }

  const Scene& s_;
  const std::vector<std::unique_ptr<Material>>& mats_;
  const RenderPlan& plan_;
  World world_;
  EnvMap env_;
  CameraRays cam_;
};

}  // namespace

RenderPlan plan_render(const Scene& scene, int spp_override) {
  RenderPlan p;
  const std::size_t delta = scene.points.size() + scene.directionals.size();
  const bool sampled = !scene.rects.empty() || scene.environment.present;
  p.max_bounces = scene.max_bounces;
  p.monte_carlo = sampled || scene.max_bounces > 0;
  const std::size_t objects = scene.spheres.size() + scene.planes.size() + scene.meshes.size();
  // A lone sphere or plane cannot shade itself beyond what cos(theta_i) <= 0 already removes.
  p.shadow_rays = objects > 1 || !scene.meshes.empty() || !scene.rects.empty();
  p.spp = p.monte_carlo ? (spp_override > 0 ? spp_override : scene.spp) : 1;
  if (delta > 0) {
    p.effects.push_back("direct light from " + std::to_string(scene.points.size()) + " point and " +
                        std::to_string(scene.directionals.size()) +
                        " directional light(s): exact, one evaluation per light");
    p.effects.push_back(p.shadow_rays
                            ? "shadows: one shadow ray per delta light per shading point"
                            : "shadows: none traced (a lone convex object cannot occlude)");
  }
  if (sampled) {
    std::string what;
    if (!scene.rects.empty()) what += std::to_string(scene.rects.size()) + " rect light(s)";
    if (scene.environment.present) {
      what += std::string(what.empty() ? "" : " and ") + "an environment " +
              (scene.environment.uniform ? "(uniform)" : "map");
    }
    p.effects.push_back("area/environment light: " + what +
                        ", Monte Carlo with MIS (one light and one BRDF sample per vertex, power "
                        "heuristic), shadow rays");
  }
  p.effects.push_back(scene.max_bounces > 0
                          ? "indirect light: " + std::to_string(scene.max_bounces) +
                                " bounce(s), BRDF importance sampling"
                          : "indirect light: none (max_bounces 0)");
  p.effects.push_back(p.monte_carlo ? "sampling: " + std::to_string(p.spp) +
                                          " jittered samples per pixel, per-pixel seeds"
                                    : "sampling: none, one ray through each pixel centre; the "
                                      "image does not depend on --spp");
  return p;
}

Image render(const Scene& scene, const std::vector<std::unique_ptr<Material>>& materials,
             const RenderPlan& plan, int threads) {
  Image img(scene.width, scene.height);
  const Integrator integrator(scene, materials, plan);
  parallel_for(scene.height, threads, [&](int y) {
    for (int x = 0; x < scene.width; ++x) {
      const Rgb c = integrator.pixel(x, y);
      for (int k = 0; k < 3; ++k) img.at(x, y, k) = float(c[k]);
    }
  });
  return img;
}

}  // namespace cbrdf::render
