#include "scenes/mesh_file_reader.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <assimp/Importer.hpp>
#include <cmath>
#include <filesystem>
#include <system_error>

namespace tumble::mesh_files {

std::string read(const std::string& path, double scale, std::size_t max_vertices,
                 std::size_t max_triangles, Arrays* out) {
  out->xyz.clear();
  out->triangles.clear();
  const std::string where = "mesh file '" + path + "': ";
  if (!(std::isfinite(scale) && scale > 0)) return where + "scale must be a finite number > 0";
  std::error_code error;
  const std::uintmax_t bytes = std::filesystem::file_size(path, error);
  if (error) return where + error.message();
  if (bytes > kMaxFileBytes)
    return where + std::to_string(bytes) + " bytes, more than the " +
           std::to_string(kMaxFileBytes) + " a mesh file may have";
  Assimp::Importer importer;
  // Points and lines are not surfaces: left out rather than refused.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  importer.SetPropertyBool(AI_CONFIG_PP_FD_REMOVE, true);
  const aiScene* scene = importer.ReadFile(
      path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                aiProcess_PreTransformVertices | aiProcess_FindDegenerates | aiProcess_SortByPType);
  if (scene == nullptr) return where + importer.GetErrorString();
  std::size_t triangles = 0, vertices = 0;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    triangles += scene->mMeshes[m]->mNumFaces;
    vertices += scene->mMeshes[m]->mNumVertices;
  }
  if (triangles > max_triangles)
    return where + std::to_string(triangles) + " triangles, more than the " +
           std::to_string(max_triangles) + " a mesh may have";
  if (vertices > max_vertices)
    return where + std::to_string(vertices) + " vertices, more than the " +
           std::to_string(max_vertices) + " a mesh may have";
  out->xyz.reserve(3 * vertices);
  out->triangles.reserve(3 * triangles);
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh& part = *scene->mMeshes[m];
    const auto first = static_cast<std::uint32_t>(out->xyz.size() / 3);
    for (unsigned v = 0; v < part.mNumVertices; ++v) {
      const aiVector3D& p = part.mVertices[v];
      for (double coordinate : {p.x, p.y, p.z})
        out->xyz.push_back(scale * coordinate);
    }
    for (unsigned f = 0; f < part.mNumFaces; ++f) {
      const aiFace& face = part.mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines, where any are left
      for (unsigned k = 0; k < 3; ++k)
        out->triangles.push_back(first + face.mIndices[k]);
    }
  }
  if (out->triangles.empty()) return where + "has no triangles";
  return "";
}

}  // namespace tumble::mesh_files
