// Convex polyhedra: the geometry behind boxes and convex hulls, with the face, edge and adjacency
// data that the separating-axis test and contact clipping need.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "physics/math.h"
#include "physics/status.h"

namespace tumble {

struct ConvexPolyhedron {
  struct Face {
    Vec3 normal;          // unit, outward
    double offset;        // plane: normal . x = offset
    std::uint32_t first;  // into face_vertices
    std::uint32_t count;  // vertices of the loop, counter-clockwise seen from outside
  };
  struct Edge {
    std::uint32_t tail, head;   // vertex indices
    std::uint32_t left, right;  // faces: `left` has tail->head in its loop, `right` head->tail
  };

  std::vector<Vec3> vertices;
  std::vector<Face> faces;
  std::vector<std::uint32_t> face_vertices;
  std::vector<Edge> edges;
  Vec3 centroid = Vec3::Zero();  // of the solid
  double volume = 0;
  // Made by make_box_polyhedron, whose layout the separating-axis test reads (sat.cc): vertex i
  // at (+-h.x, +-h.y, +-h.z), + where bit 0, 1, 2 of i is set; faces -x, +x, -y, +y, -z, +z.
  bool box = false;

  // Index of the vertex farthest along `direction` (ties: the lowest index).
  std::uint32_t support_index(const Vec3& direction) const {
    std::uint32_t best = 0;
    double best_dot = vertices[0].dot(direction);
    for (std::uint32_t i = 1; i < vertices.size(); ++i) {
      const double d = vertices[i].dot(direction);
      if (d > best_dot) {
        best_dot = d;
        best = i;
      }
    }
    return best;
  }
  Vec3 support(const Vec3& direction) const { return vertices[support_index(direction)]; }
  Vec3 face_vertex(const Face& face, std::uint32_t k) const {
    return vertices[face_vertices[face.first + k % face.count]];
  }
};

// The box [-h, h]^3 as a polyhedron: 8 vertices, 6 faces, 12 edges.
ConvexPolyhedron make_box_polyhedron(const Vec3& half_extents);

// The convex hull of a point cloud (Qhull, Barber et al. 1996), with coplanar facets merged into
// polygons and duplicate or interior points dropped. Fails with a message when the points are
// fewer than 4, not finite, or span no volume (coplanar, collinear, coincident).
Result<ConvexPolyhedron> build_convex_hull(std::span<const Vec3> points);

}  // namespace tumble
