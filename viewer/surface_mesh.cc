#include "surface_mesh.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace tumble::viewer {

Mesh surface_mesh(std::span<const double> xyz, std::span<const std::uint32_t> indices) {
  Mesh mesh;
  if (xyz.size() % 3 != 0 || indices.size() % 3 != 0) return mesh;
  const std::size_t vertex_count = xyz.size() / 3;
  for (std::uint32_t index : indices)
    if (index >= vertex_count) return mesh;
  const auto at = [&](std::uint32_t index) {
    return Eigen::Vector3d(xyz[3 * index], xyz[3 * index + 1], xyz[3 * index + 2]);
  };
  mesh.vertices.reserve(3 * indices.size() * 2);
  mesh.indices.reserve(indices.size());
  for (std::size_t t = 0; t < indices.size(); t += 3) {
    const Eigen::Vector3d a = at(indices[t]), b = at(indices[t + 1]), c = at(indices[t + 2]);
    const Eigen::Vector3d n = (b - a).cross(c - a);
    if (!(n.norm() > 0)) continue;
    const Eigen::Vector3d unit = n.normalized();
    for (const Eigen::Vector3d& p : {a, b, c}) {
      mesh.indices.push_back(static_cast<std::uint32_t>(mesh.vertices.size() / 6));
      for (double value : {p.x(), p.y(), p.z(), unit.x(), unit.y(), unit.z()})
        mesh.vertices.push_back(static_cast<float>(value));
    }
  }
  return mesh;
}

}  // namespace tumble::viewer
