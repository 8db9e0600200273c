#include "scenes/mesh_file.h"

#include "scenes/mesh_file_reader.h"

namespace tumble {

Result<TriangleMeshDef> read_mesh_file(const std::string& path, double scale) {
  mesh_files::Arrays arrays;
  if (std::string error =
          mesh_files::read(path, scale, kMaxMeshVertices, kMaxMeshTriangles, &arrays);
      !error.empty())
    return Status::error(error);
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

}  // namespace tumble
