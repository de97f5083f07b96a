// SPDX-License-Identifier: MIT
// Triangle meshes for the renderer: Draco loading (.drc, and .obj/.ply through Draco's readers),
// Draco writing (for the built-in scenes), and a BVH for ray queries.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <vector>

#include "cbrdf/status.h"
#include "render/vec.h"

namespace cbrdf::render {

struct MeshHit {
  double t = std::numeric_limits<double>::infinity();
  int triangle = -1;
  double b1 = 0, b2 = 0;  // barycentrics of vertices 1 and 2
};

class TriangleMesh {
 public:
  std::vector<Vec3> positions;
  std::vector<Vec3> normals;  // per vertex, or empty (flat shading)
  std::vector<std::array<std::uint32_t, 3>> triangles;

  // Applies scale then translation, and builds the BVH (median split on the widest centroid axis,
  // up to 4 triangles per leaf). Call once after filling the arrays.
  void finalize(double scale, const Vec3& translate);

  // Nearest hit with t in (t_min, hit->t); true when one was found.
  bool intersect(const Ray& ray, double t_min, MeshHit* hit) const;
  // Any hit with t in (t_min, t_max).
  bool occluded(const Ray& ray, double t_min, double t_max) const;
  // Geometric (face) normal and shading normal at a hit.
  Vec3 geometric_normal(int triangle) const;
  Vec3 shading_normal(const MeshHit& hit) const;

  Vec3 bounds_min() const { return nodes_.empty() ? Vec3{} : nodes_[0].lo; }
  Vec3 bounds_max() const { return nodes_.empty() ? Vec3{} : nodes_[0].hi; }

 private:
  struct Node {
    Vec3 lo, hi;
    int first = 0, count = 0;  // leaf: triangles [first, first + count) of order_
    int left = -1, right = -1;
  };
  int build(int first, int count, std::vector<Vec3>* centroids);
  bool hit_triangle(int tri, const Ray& ray, double t_min, double t_max, MeshHit* hit) const;
  std::vector<Node> nodes_;
  std::vector<int> order_;
};

// Reads a mesh with Draco: .drc through draco::Decoder, anything else through
// draco::ReadMeshFromFile (.obj, .ply, .stl). Errors name the file.
Expected<TriangleMesh> load_mesh(const std::filesystem::path& path);

// Writes positions and normals (if any) as a Draco .drc (quantized: 14-bit positions, 10-bit
// normals), atomically.
Status write_drc(const std::filesystem::path& path, const TriangleMesh& mesh);

}  // namespace cbrdf::render
