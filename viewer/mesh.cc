#include "mesh.h"

#include <cmath>
#include <numbers>

namespace tumble::viewer {
namespace {

void add_vertex(Mesh* mesh, float x, float y, float z, float nx, float ny, float nz) {
  for (float value : {x, y, z, nx, ny, nz})
    mesh->vertices.push_back(value);
}

// A latitude-longitude band structure over `rings` + 1 rows of `segments` + 1 vertices.
void add_grid_indices(Mesh* mesh, std::uint32_t first, int rows, int segments) {
  const auto row = static_cast<std::uint32_t>(segments + 1);
  for (int r = 0; r < rows; ++r)
    for (int s = 0; s < segments; ++s) {
      const std::uint32_t a = first + r * row + s, b = a + row;
      mesh->indices.insert(mesh->indices.end(), {a, b, a + 1, a + 1, b, b + 1});
    }
}

}  // namespace

Mesh unit_box() {
  Mesh mesh;
  // Each face: its normal axis and sign; corners counter-clockwise seen from outside.
  for (int axis = 0; axis < 3; ++axis)
    for (float sign : {-1.0f, 1.0f}) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      const auto first = static_cast<std::uint32_t>(mesh.vertices.size() / 6);
      const float corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
      for (const auto& c : corners) {
        float p[3], n[3] = {0, 0, 0};
        p[axis] = sign;
        p[u] = c[0];
        p[v] = sign > 0 ? c[1] : -c[1];  // mirrored so the winding faces outward
        n[axis] = sign;
        add_vertex(&mesh, p[0], p[1], p[2], n[0], n[1], n[2]);
      }
      mesh.indices.insert(mesh.indices.end(),
                          {first, first + 1, first + 2, first, first + 2, first + 3});
    }
  return mesh;
}

Mesh unit_sphere(int rings, int segments) {
  Mesh mesh;
  for (int r = 0; r <= rings; ++r) {
    const double polar = std::numbers::pi * r / rings;  // from +z down
    for (int s = 0; s <= segments; ++s) {
      const double azimuth = 2 * std::numbers::pi * s / segments;
      const auto x = static_cast<float>(std::sin(polar) * std::cos(azimuth));
      const auto y = static_cast<float>(std::sin(polar) * std::sin(azimuth));
      const auto z = static_cast<float>(std::cos(polar));
      add_vertex(&mesh, x, y, z, x, y, z);
    }
  }
  add_grid_indices(&mesh, 0, rings, segments);
  return mesh;
}

Mesh capsule(float radius, float half_height, int rings, int segments) {
  Mesh mesh;
  // Two hemispheres of `rings` bands each, the upper one raised and the lower one lowered by
  // half_height; the band between them is the cylinder.
  const int rows = 2 * rings + 1;
  for (int r = 0; r <= rows; ++r) {
    const bool upper = r <= rings;
    const double polar = std::numbers::pi / 2 * (upper ? r : r - 1) / rings;
    const double offset = upper ? half_height : -half_height;
    for (int s = 0; s <= segments; ++s) {
      const double azimuth = 2 * std::numbers::pi * s / segments;
      const auto nx = static_cast<float>(std::sin(polar) * std::cos(azimuth));
      const auto ny = static_cast<float>(std::sin(polar) * std::sin(azimuth));
      const auto nz = static_cast<float>(std::cos(polar));
      add_vertex(&mesh, radius * nx, radius * ny, static_cast<float>(radius * nz + offset), nx, ny,
                 nz);
    }
  }
  add_grid_indices(&mesh, 0, rows, segments);
  return mesh;
}

Mesh ground_square(float half) {
  Mesh mesh;
  add_vertex(&mesh, -half, -half, 0, 0, 0, 1);
  add_vertex(&mesh, half, -half, 0, 0, 0, 1);
  add_vertex(&mesh, half, half, 0, 0, 0, 1);
  add_vertex(&mesh, -half, half, 0, 0, 0, 1);
  mesh.indices = {0, 1, 2, 0, 2, 3};
  return mesh;
}

}  // namespace tumble::viewer
