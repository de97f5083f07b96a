// SPDX-License-Identifier: MIT
// Light sampling for the Monte Carlo integrator: environment maps (piecewise-constant importance
// sampling over lat-long pixels) and rectangular area lights (uniform over the area).
#pragma once

#include <vector>

#include "render/scene.h"

namespace cbrdf::render {

class EnvMap {
 public:
  explicit EnvMap(const EnvironmentLight& light);
  bool present() const { return present_; }
  Rgb radiance(const Vec3& dir) const;
  // A direction drawn with density pdf() per unit solid angle; *pdf = 0 when nothing emits.
  Vec3 sample(double u1, double u2, double* pdf) const;
  double pdf(const Vec3& dir) const;

 private:
  int pixel_of(const Vec3& dir) const;
  bool present_ = false, uniform_ = true;
  Rgb scale_{};
  const Image* map_ = nullptr;
  std::vector<double> row_cdf_;  // height + 1
  std::vector<double> col_cdf_;  // height * (width + 1), conditional per row
  std::vector<double> p_;        // probability per pixel
};

// Uniform point on a rect light; the density in solid angle seen from `from`, and the radiance
// arriving (0 from the back side).
struct RectSample {
  Vec3 wi;          // unit, from `from` toward the point
  double dist = 0;  // to the point
  double pdf = 0;   // per unit solid angle; 0 when the back side faces `from`
};
RectSample sample_rect(const RectLight& r, const Vec3& from, double u1, double u2);
// Solid-angle density of sample_rect for a ray from `from` hitting the light at distance dist.
double rect_pdf(const RectLight& r, const Vec3& dir, double dist);
// Ray-rect intersection: distance in (t_min, t_max), or < 0 for a miss.
double hit_rect(const RectLight& r, const Ray& ray, double t_min, double t_max);
// Radiance leaving the light toward -dir (0 from the back side).
Rgb rect_emission(const RectLight& r, const Vec3& dir);

}  // namespace cbrdf::render
