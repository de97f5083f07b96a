// SPDX-License-Identifier: MIT
// TriangleMesh: BVH and ray queries.
#include "render/mesh.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace cbrdf::render {
namespace {

// Slab test of a ray against a box, over (t_min, t_max).
bool hit_box(const Vec3& lo, const Vec3& hi, const Ray& ray, const Vec3& inv, double t_min,
             double t_max) {
  for (int a = 0; a < 3; ++a) {
    const double o = component(ray.origin, a), i = component(inv, a);
    double t0 = (component(lo, a) - o) * i, t1 = (component(hi, a) - o) * i;
    if (t0 > t1) std::swap(t0, t1);
    // NaN (0 * inf on a slab face) must not reject the box: max/min with NaN keep the bound.
    if (t0 > t_min) t_min = t0;
    if (t1 < t_max) t_max = t1;
    if (t_min > t_max) return false;
  }
  return true;
}

}  // namespace

void TriangleMesh::finalize(double scale, const Vec3& translate) {
  for (Vec3& p : positions) p = p * scale + translate;
  if (scale < 0) {
    for (Vec3& n : normals) n = -n;
  }
  std::vector<Vec3> centroids(triangles.size());
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    const auto& t = triangles[i];
    centroids[i] = (positions[t[0]] + positions[t[1]] + positions[t[2]]) * (1.0 / 3);
  }
  order_.resize(triangles.size());
  std::iota(order_.begin(), order_.end(), 0);
  nodes_.clear();
  nodes_.reserve(2 * triangles.size() + 1);
  if (!triangles.empty()) build(0, int(triangles.size()), &centroids);
}

int TriangleMesh::build(int first, int count, std::vector<Vec3>* centroids) {
  const int index = int(nodes_.size());
  nodes_.push_back({});
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  Vec3 clo = lo, chi = hi;
  for (int i = first; i < first + count; ++i) {
    const auto& t = triangles[std::size_t(order_[i])];
    for (int k = 0; k < 3; ++k) {
      lo = vmin(lo, positions[t[k]]);
      hi = vmax(hi, positions[t[k]]);
    }
    clo = vmin(clo, (*centroids)[std::size_t(order_[i])]);
    chi = vmax(chi, (*centroids)[std::size_t(order_[i])]);
  }
  nodes_[index].lo = lo;
  nodes_[index].hi = hi;
  const Vec3 extent = chi - clo;
  const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
  if (count <= 4 || component(extent, axis) <= 0) {
    nodes_[index].first = first;
    nodes_[index].count = count;
    return index;
  }
  const int mid = first + count / 2;
  std::nth_element(order_.begin() + first, order_.begin() + mid, order_.begin() + first + count,
                   [&](int a, int b) {
                     return component((*centroids)[std::size_t(a)], axis) <
                            component((*centroids)[std::size_t(b)], axis);
                   });
  const int left = build(first, mid - first, centroids);
  const int right = build(mid, first + count - mid, centroids);
  nodes_[index].left = left;
  nodes_[index].right = right;
  return index;
}

// Moller-Trumbore.
bool TriangleMesh::hit_triangle(int tri, const Ray& ray, double t_min, double t_max,
                                MeshHit* hit) const {
  const auto& t = triangles[std::size_t(tri)];
  const Vec3 &p0 = positions[t[0]], &p1 = positions[t[1]], &p2 = positions[t[2]];
  const Vec3 e1 = p1 - p0, e2 = p2 - p0;
  const Vec3 pv = cross(ray.dir, e2);
  const double det = dot(e1, pv);
  if (std::abs(det) < 1e-300) return false;
  const double inv = 1.0 / det;
  const Vec3 tv = ray.origin - p0;
  const double u = dot(tv, pv) * inv;
  if (u < 0 || u > 1) return false;
  const Vec3 qv = cross(tv, e1);
  const double v = dot(ray.dir, qv) * inv;
  if (v < 0 || u + v > 1) return false;
  const double d = dot(e2, qv) * inv;
  if (!(d > t_min && d < t_max)) return false;
  if (hit != nullptr) *hit = {d, tri, u, v};
  return true;
}

bool TriangleMesh::intersect(const Ray& ray, double t_min, MeshHit* hit) const {
  if (nodes_.empty()) return false;
  const Vec3 inv{1 / ray.dir.x, 1 / ray.dir.y, 1 / ray.dir.z};
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  bool found = false;
  while (top > 0) {
    const Node& n = nodes_[std::size_t(stack[--top])];
    if (!hit_box(n.lo, n.hi, ray, inv, t_min, hit->t)) continue;
    if (n.left < 0) {
      for (int i = n.first; i < n.first + n.count; ++i) {
        if (hit_triangle(order_[i], ray, t_min, hit->t, hit)) found = true;
      }
    } else if (top + 2 <= 128) {
      stack[top++] = n.left;
      stack[top++] = n.right;
    }
  }
  return found;
}

bool TriangleMesh::occluded(const Ray& ray, double t_min, double t_max) const {
  if (nodes_.empty() || !(t_max > t_min)) return false;
  const Vec3 inv{1 / ray.dir.x, 1 / ray.dir.y, 1 / ray.dir.z};
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[std::size_t(stack[--top])];
    if (!hit_box(n.lo, n.hi, ray, inv, t_min, t_max)) continue;
    if (n.left < 0) {
      for (int i = n.first; i < n.first + n.count; ++i) {
        if (hit_triangle(order_[i], ray, t_min, t_max, nullptr)) return true;
      }
    } else if (top + 2 <= 128) {
      stack[top++] = n.left;
      stack[top++] = n.right;
    }
  }
  return false;
}

Vec3 TriangleMesh::geometric_normal(int triangle) const {
  const auto& t = triangles[std::size_t(triangle)];
  return normalize(cross(positions[t[1]] - positions[t[0]], positions[t[2]] - positions[t[0]]));
}

Vec3 TriangleMesh::shading_normal(const MeshHit& hit) const {
  if (normals.empty()) return geometric_normal(hit.triangle);
  const auto& t = triangles[std::size_t(hit.triangle)];
  const Vec3 n =
      normals[t[0]] * (1 - hit.b1 - hit.b2) + normals[t[1]] * hit.b1 + normals[t[2]] * hit.b2;
  const double l = length(n);
  return l > 0 ? n * (1 / l) : geometric_normal(hit.triangle);
}

}  // namespace cbrdf::render
