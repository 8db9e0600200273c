// The separating-axis test between two convex polyhedra.
//
// Source: Gregorius, "The Separating Axis Test between Convex Polyhedra", GDC 2013. A pair of
// edges only needs its cross product tested when the edges form a face of the Minkowski
// difference, which is the case exactly when their arcs on the Gauss map cross; that prunes most of
// the |E_A| x |E_B| pairs and, more importantly, every axis it keeps is a true candidate.
//
// Steps: (1) face normals of A against B's support; (2) the same for B; (3) Minkowski-face edge
// pairs; the largest separation names the axis. Exact: no iteration, no tolerance but the one
// that decides whether two edges are parallel.
#pragma once

#include "manifold.h"

namespace tumble {

struct FaceQuery {
  std::uint32_t face = 0;
  double separation = -std::numeric_limits<double>::infinity();
};

struct EdgeQuery {
  std::uint32_t edge_a = 0, edge_b = 0;
  double separation = -std::numeric_limits<double>::infinity();
  Vec3 axis = Vec3::UnitZ();  // from A towards B
};

// Faces of `faces` (placed) against the vertices of `other` (placed), all in one frame.
FaceQuery query_faces(const PlacedPolyhedron& faces, const PlacedPolyhedron& other);
EdgeQuery query_edges(const PlacedPolyhedron& a, const PlacedPolyhedron& b);
// The same for one face, or one pair of edges (separation -infinity when they are parallel),
// with the same arithmetic: a feature found before, measured again.
FaceQuery query_face(const PlacedPolyhedron& faces, std::uint32_t face,
                     const PlacedPolyhedron& other);
EdgeQuery query_edge_pair(const PlacedPolyhedron& a, std::uint32_t edge_a,
                          const PlacedPolyhedron& b, std::uint32_t edge_b);

}  // namespace tumble
