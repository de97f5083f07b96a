// SPDX-License-Identifier: MIT
#include "render/lights.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace cbrdf::render {
namespace {

constexpr double kPi = std::numbers::pi;

int pick(const double* cdf, int n, double* u) {
  const double* it = std::upper_bound(cdf, cdf + n + 1, *u);
  const int i = std::clamp(int(it - cdf) - 1, 0, n - 1);
  const double w = cdf[i + 1] - cdf[i];
  *u = w > 0 ? std::clamp((*u - cdf[i]) / w, 0.0, std::nextafter(1.0, 0.0)) : 0.5;
  return i;
}

Vec3 rect_normal(const RectLight& r) {
  return normalize(cross(r.edge1, r.edge2));
}
double rect_area(const RectLight& r) {
  return length(cross(r.edge1, r.edge2));
}

}  // namespace

EnvMap::EnvMap(const EnvironmentLight& light)
    : present_(light.present), uniform_(light.uniform), scale_(light.radiance) {
  if (!present_ || uniform_) return;
  map_ = &light.map;
  const int w = map_->width, h = map_->height;
  p_.assign(std::size_t(w) * h, 0.0);
  double total = 0;
  for (int y = 0; y < h; ++y) {
    const double sin_theta = std::sin((y + 0.5) / h * kPi);
    for (int x = 0; x < w; ++x) {
      const double v = (scale_[0] * map_->at(x, y, 0) + scale_[1] * map_->at(x, y, 1) +
                        scale_[2] * map_->at(x, y, 2)) /
                       3 * sin_theta;
      p_[std::size_t(y) * w + x] = v;
      total += v;
    }
  }
  row_cdf_.assign(std::size_t(h) + 1, 0.0);
  col_cdf_.assign(std::size_t(h) * (w + 1), 0.0);
  if (!(total > 0)) return;  // a black map: nothing to sample
  double run = 0;
  for (int y = 0; y < h; ++y) {
    double* cdf = &col_cdf_[std::size_t(y) * (w + 1)];
    double row = 0;
    for (int x = 0; x < w; ++x) {
      double& p = p_[std::size_t(y) * w + x];
      p /= total;
      row += p;
      cdf[x + 1] = row;
    }
    for (int x = 1; x <= w; ++x) cdf[x] = row > 0 ? cdf[x] / row : double(x) / w;
    cdf[w] = 1;
    run += row;
    row_cdf_[y + 1] = run;
  }
  for (double& v : row_cdf_) v /= run;
  row_cdf_[h] = 1;
}

int EnvMap::pixel_of(const Vec3& d) const {
  const int w = map_->width, h = map_->height;
  const double u = (std::atan2(d.x, -d.z) + kPi) / (2 * kPi);
  const double v = std::acos(std::clamp(d.y, -1.0, 1.0)) / kPi;
  const int x = std::clamp(int(u * w), 0, w - 1), y = std::clamp(int(v * h), 0, h - 1);
  return y * w + x;
}

Rgb EnvMap::radiance(const Vec3& dir) const {
  if (!present_) return {0, 0, 0};
  if (uniform_) return scale_;
  const std::size_t i = std::size_t(pixel_of(dir)) * 3;
  return {scale_[0] * map_->data[i], scale_[1] * map_->data[i + 1], scale_[2] * map_->data[i + 2]};
}

Vec3 EnvMap::sample(double u1, double u2, double* pdf) const {
  *pdf = 0;
  if (!present_) return {0, 1, 0};
  if (uniform_) {
    const double z = 1 - 2 * u1, r = std::sqrt(std::max(0.0, 1 - z * z)), phi = 2 * kPi * u2;
    *pdf = 1 / (4 * kPi);
    return {r * std::cos(phi), z, r * std::sin(phi)};
  }
  if (row_cdf_.back() != 1.0 || p_.empty()) return {0, 1, 0};
  const int w = map_->width, h = map_->height;
  const int y = pick(row_cdf_.data(), h, &u1);
  const int x = pick(&col_cdf_[std::size_t(y) * (w + 1)], w, &u2);
  const double theta = (y + u1) / h * kPi, phi = (x + u2) / w * 2 * kPi - kPi;
  const Vec3 d{std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi)};
  *pdf = this->pdf(d);
  return d;
}

double EnvMap::pdf(const Vec3& dir) const {
  if (!present_) return 0;
  if (uniform_) return 1 / (4 * kPi);
  if (p_.empty() || row_cdf_.back() != 1.0) return 0;
  const double sin_theta = std::sqrt(std::max(0.0, 1 - dir.y * dir.y));
  if (!(sin_theta > 0)) return 0;
  return p_[std::size_t(pixel_of(dir))] * double(map_->width) * map_->height /
         (2 * kPi * kPi * sin_theta);
}

RectSample sample_rect(const RectLight& r, const Vec3& from, double u1, double u2) {
  RectSample s;
  const Vec3 q = r.corner + r.edge1 * u1 + r.edge2 * u2;
  const Vec3 d = q - from;
  s.dist = length(d);
  if (!(s.dist > 0)) return s;
  s.wi = d * (1 / s.dist);
  s.pdf = rect_pdf(r, s.wi, s.dist);
  return s;
}

double rect_pdf(const RectLight& r, const Vec3& dir, double dist) {
  const double cos_l = -dot(dir, rect_normal(r));
  if (!(cos_l > 0)) return 0;
  return dist * dist / (rect_area(r) * cos_l);
}

double hit_rect(const RectLight& r, const Ray& ray, double t_min, double t_max) {
  const Vec3 n = cross(r.edge1, r.edge2);
  const double denom = dot(ray.dir, n);
  if (denom == 0) return -1;
  const double t = dot(r.corner - ray.origin, n) / denom;
  if (!(t > t_min && t < t_max)) return -1;
  const Vec3 q = ray.origin + ray.dir * t - r.corner;
  const double e11 = dot(r.edge1, r.edge1), e22 = dot(r.edge2, r.edge2),
               e12 = dot(r.edge1, r.edge2);
  const double q1 = dot(q, r.edge1), q2 = dot(q, r.edge2);
  const double det = e11 * e22 - e12 * e12;
  const double a = (q1 * e22 - q2 * e12) / det, b = (q2 * e11 - q1 * e12) / det;
  return a >= 0 && a <= 1 && b >= 0 && b <= 1 ? t : -1;
}

Rgb rect_emission(const RectLight& r, const Vec3& dir) {
  return dot(dir, rect_normal(r)) < 0 ? r.radiance : Rgb{0, 0, 0};
}

}  // namespace cbrdf::render
