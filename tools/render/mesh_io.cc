// SPDX-License-Identifier: MIT
// Draco mesh reading and writing.
#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/io/mesh_io.h>
#include <draco/mesh/triangle_soup_mesh_builder.h>

#include <string>

#include "cbrdf/file_io.h"
#include "render/mesh.h"

namespace cbrdf::render {
namespace {

constexpr std::uint64_t kMaxMeshFileBytes = std::uint64_t{1} << 30;

Expected<TriangleMesh> from_draco(const draco::Mesh& dm, const std::string& name) {
  const draco::PointAttribute* pos = dm.GetNamedAttribute(draco::GeometryAttribute::POSITION);
  if (pos == nullptr) return error(ErrorCode::kCorrupt, name + ": the mesh has no positions");
  const draco::PointAttribute* nrm = dm.GetNamedAttribute(draco::GeometryAttribute::NORMAL);
  TriangleMesh m;
  const std::size_t points = dm.num_points();
  m.positions.resize(points);
  if (nrm != nullptr) m.normals.resize(points);
  for (std::size_t p = 0; p < points; ++p) {
    const draco::PointIndex pi(static_cast<std::uint32_t>(p));
    float v[3] = {0, 0, 0};
    if (!pos->ConvertValue<float, 3>(pos->mapped_index(pi), v)) {
      return error(ErrorCode::kCorrupt,
                   name + ": unreadable position of point " + std::to_string(p));
    }
    m.positions[p] = {v[0], v[1], v[2]};
    if (nrm != nullptr) {
      float n[3] = {0, 0, 0};
      if (!nrm->ConvertValue<float, 3>(nrm->mapped_index(pi), n)) {
        return error(ErrorCode::kCorrupt,
                     name + ": unreadable normal of point " + std::to_string(p));
      }
      m.normals[p] = normalize(Vec3{n[0], n[1], n[2]});
    }
  }
  m.triangles.reserve(dm.num_faces());
  for (draco::FaceIndex f(0); f < dm.num_faces(); ++f) {
    const draco::Mesh::Face& face = dm.face(f);
    m.triangles.push_back({face[0].value(), face[1].value(), face[2].value()});
  }
  if (m.triangles.empty()) return error(ErrorCode::kCorrupt, name + ": the mesh has no triangles");
  return m;
}

}  // namespace

Expected<TriangleMesh> load_mesh(const std::filesystem::path& path) {
  const std::string name = path.string();
  if (!std::filesystem::exists(path)) {
    return error(ErrorCode::kNotFound, name + ": no such file");
  }
  std::unique_ptr<draco::Mesh> mesh;
  if (path.extension() == ".drc") {
    CBRDF_ASSIGN_OR_RETURN(auto bytes, read_file(path, kMaxMeshFileBytes));
    draco::DecoderBuffer buffer;
    buffer.Init(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    draco::Decoder decoder;
    auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
    if (!decoded.ok()) {
      return error(ErrorCode::kCorrupt,
                   name + ": not a Draco mesh: " + decoded.status().error_msg_string());
    }
    mesh = std::move(decoded).value();
  } else {
    auto read = draco::ReadMeshFromFile(name);
    if (!read.ok()) {
      return error(ErrorCode::kCorrupt,
                   name + ": Draco could not read the mesh: " + read.status().error_msg_string());
    }
    mesh = std::move(read).value();
  }
  if (mesh == nullptr) return error(ErrorCode::kCorrupt, name + ": no mesh in the file");
  return from_draco(*mesh, name);
}

Status write_drc(const std::filesystem::path& path, const TriangleMesh& mesh) {
  draco::TriangleSoupMeshBuilder builder;
  builder.Start(int(mesh.triangles.size()));
  const int pos = builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
  const int nrm = mesh.normals.empty() ? -1
                                       : builder.AddAttribute(draco::GeometryAttribute::NORMAL, 3,
                                                              draco::DT_FLOAT32);
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    float p[3][3], n[3][3];
    for (int k = 0; k < 3; ++k) {
      const Vec3& v = mesh.positions[mesh.triangles[f][k]];
      p[k][0] = float(v.x), p[k][1] = float(v.y), p[k][2] = float(v.z);
      if (nrm >= 0) {
        const Vec3& w = mesh.normals[mesh.triangles[f][k]];
        n[k][0] = float(w.x), n[k][1] = float(w.y), n[k][2] = float(w.z);
      }
    }
    const draco::FaceIndex fi(static_cast<std::uint32_t>(f));
    builder.SetAttributeValuesForFace(pos, fi, p[0], p[1], p[2]);
    if (nrm >= 0) builder.SetAttributeValuesForFace(nrm, fi, n[0], n[1], n[2]);
  }
  std::unique_ptr<draco::Mesh> dm = builder.Finalize();
  if (dm == nullptr) return error(ErrorCode::kInternal, path.string() + ": Draco refused the mesh");
  draco::Encoder encoder;
  encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, 14);
  encoder.SetAttributeQuantization(draco::GeometryAttribute::NORMAL, 10);
  draco::EncoderBuffer buffer;
  const draco::Status s = encoder.EncodeMeshToBuffer(*dm, &buffer);
  if (!s.ok()) {
    return error(ErrorCode::kInternal,
                 path.string() + ": Draco encoding failed: " + s.error_msg_string());
  }
  const auto* data = reinterpret_cast<const std::uint8_t*>(buffer.data());
  return write_file_atomic(path, std::span<const std::uint8_t>(data, buffer.size()));
}

}  // namespace cbrdf::render
