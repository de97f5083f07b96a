// SPDX-License-Identifier: MIT
// Small vector helpers for the renderer, on cbrdf::Vec3 (world space, y up).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

#include "cbrdf/coords.h"

namespace cbrdf::render {

using Rgb = std::array<double, 3>;

inline Vec3 operator+(const Vec3& a, const Vec3& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
inline Vec3 operator-(const Vec3& a, const Vec3& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
inline Vec3 operator-(const Vec3& a) {
  return {-a.x, -a.y, -a.z};
}
inline Vec3 operator*(const Vec3& a, double s) {
  return {a.x * s, a.y * s, a.z * s};
}
inline Vec3 operator*(double s, const Vec3& a) {
  return a * s;
}
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double length(const Vec3& a) {
  return std::sqrt(dot(a, a));
}
inline Vec3 normalize(const Vec3& a) {
  const double l = length(a);
  return l > 0 ? a * (1.0 / l) : a;
}
inline double component(const Vec3& a, int axis) {
  return axis == 0 ? a.x : axis == 1 ? a.y : a.z;
}
inline Vec3 vmin(const Vec3& a, const Vec3& b) {
  return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
inline Vec3 vmax(const Vec3& a, const Vec3& b) {
  return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}

inline Rgb operator*(const Rgb& a, const Rgb& b) {
  return {a[0] * b[0], a[1] * b[1], a[2] * b[2]};
}
inline Rgb operator*(const Rgb& a, double s) {
  return {a[0] * s, a[1] * s, a[2] * s};
}
inline Rgb& operator+=(Rgb& a, const Rgb& b) {
  for (int c = 0; c < 3; ++c) a[c] += b[c];
  return a;
}
inline double mean(const Rgb& a) {
  return (a[0] + a[1] + a[2]) / 3;
}
inline bool is_black(const Rgb& a) {
  return a[0] == 0 && a[1] == 0 && a[2] == 0;
}

// An orthonormal frame around a unit normal (Duff et al. 2017), as metrics.h's sphere renders use.
struct Frame {
  Vec3 t, b, n;
  explicit Frame(const Vec3& normal) : n(normal) {
    const double sign = std::copysign(1.0, n.z);
    const double a = -1.0 / (sign + n.z);
    const double c = n.x * n.y * a;
    t = {1.0 + sign * n.x * n.x * a, sign * c, -sign * n.x};
    b = {c, sign + n.y * n.y * a, -n.y};
  }
  Vec3 to_local(const Vec3& w) const { return {dot(w, t), dot(w, b), dot(w, n)}; }
  Vec3 to_world(const Vec3& w) const { return t * w.x + b * w.y + n * w.z; }
};

struct Ray {
  Vec3 origin, dir;  // dir is unit length
};

}  // namespace cbrdf::render
