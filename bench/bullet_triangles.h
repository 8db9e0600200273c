// A triangle mesh handed to Bullet: its vertices and indices copied into the arrays Bullet's mesh
// interface reads (single precision, as the float build stores them), kept alive with it.
#pragma once

#include <btBulletCollisionCommon.h>

#include <memory>
#include <vector>

#include "physics/triangle_mesh.h"

namespace tumble {

struct BulletTriangles {
  explicit BulletTriangles(const TriangleMeshDef& mesh) {
    for (const Vec3& v : mesh.vertices)
      for (int k = 0; k < 3; ++k)
        vertices.push_back(static_cast<float>(v[k]));
    for (const auto& t : mesh.triangles)
      for (std::uint32_t index : t)
        indices.push_back(static_cast<int>(index));
    arrays = std::make_unique<btTriangleIndexVertexArray>(
        static_cast<int>(mesh.triangles.size()), indices.data(), 3 * sizeof(int),
        static_cast<int>(mesh.vertices.size()), vertices.data(), 3 * sizeof(float));
  }
  std::vector<float> vertices;
  std::vector<int> indices;
  std::unique_ptr<btTriangleIndexVertexArray> arrays;
};

}  // namespace tumble
