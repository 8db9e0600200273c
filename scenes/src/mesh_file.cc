#include "scenes/mesh_file.h"

#include "scenes/hull_points.h"
#include "scenes/mesh_file_reader.h"

namespace tumble {

static_assert(mesh_files::kMaxHullInputPoints == kMaxHullPoints,
              "the hull reduction keeps as many points as the engine takes");

namespace {

// The file's arrays within the engine's mesh limits, or the error naming the file.
Status read_arrays(const std::string& path, double scale, mesh_files::Arrays* arrays) {
  std::string error = mesh_files::read(path, scale, kMaxMeshVertices, kMaxMeshTriangles, arrays);
  return error.empty() ? Status::ok() : Status::error(error);
}

}  // namespace

Result<TriangleMeshDef> read_mesh_file(const std::string& path, double scale) {
  mesh_files::Arrays arrays;
  if (Status s = read_arrays(path, scale, &arrays); !s) return s;
  TriangleMeshDef mesh;
  mesh.vertices.reserve(arrays.xyz.size() / 3);
  for (std::size_t k = 0; k < arrays.xyz.size(); k += 3)
    mesh.vertices.emplace_back(arrays.xyz[k], arrays.xyz[k + 1], arrays.xyz[k + 2]);
  mesh.triangles.reserve(arrays.triangles.size() / 3);
  for (std::size_t k = 0; k < arrays.triangles.size(); k += 3)
    mesh.triangles.push_back(
        {arrays.triangles[k], arrays.triangles[k + 1], arrays.triangles[k + 2]});
  return mesh;
}

Result<HullDef> read_hull_file(const std::string& path, double scale) {
  mesh_files::Arrays arrays;
  if (Status s = read_arrays(path, scale, &arrays); !s) return s;
  HullDef hull;
  for (std::size_t i : mesh_files::hull_point_indices(arrays.xyz, kMaxHullPoints))
    hull.points.emplace_back(arrays.xyz[3 * i], arrays.xyz[3 * i + 1], arrays.xyz[3 * i + 2]);
  return hull;
}

}  // namespace tumble
