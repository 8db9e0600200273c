#include "sat.h"

namespace tumble {

FaceQuery query_faces(const PlacedPolyhedron& faces, const PlacedPolyhedron& other) {
  // Work in `other`'s local frame: the support query is then a plain loop over its vertices.
  const Mat3 to_other = other.rotation.transpose() * faces.rotation;
  const Vec3 origin = other.rotation.transpose() * (faces.translation - other.translation);
  FaceQuery best;
  const auto& list = faces.polyhedron->faces;
  for (std::uint32_t f = 0; f < list.size(); ++f) {
    const Vec3 n = to_other * list[f].normal;
    const double offset = list[f].offset + n.dot(origin);
    const Vec3 deepest = other.polyhedron->support(-n);
    const double separation = n.dot(deepest) - offset;
    if (separation > best.separation) {
      best.separation = separation;
      best.face = f;
    }
  }
  return best;
}

EdgeQuery query_edges(const PlacedPolyhedron& a, const PlacedPolyhedron& b) {
  // B's edges and normals in A's frame, transformed once.
  const Mat3 rotation = a.rotation.transpose() * b.rotation;
  const Vec3 translation = a.rotation.transpose() * (b.translation - a.translation);
  const ConvexPolyhedron& pa = *a.polyhedron;
  const ConvexPolyhedron& pb = *b.polyhedron;
  thread_local std::vector<Vec3> b_vertices, b_normals;
  b_vertices.resize(pb.vertices.size());
  b_normals.resize(pb.faces.size());
  for (std::size_t i = 0; i < pb.vertices.size(); ++i)
    b_vertices[i] = rotation * pb.vertices[i] + translation;
  for (std::size_t i = 0; i < pb.faces.size(); ++i)
    b_normals[i] = rotation * pb.faces[i].normal;
  // B's Gauss-map arcs (the planes through its edges' two normals), negated for the Minkowski
  // difference A - B, and A's.
  thread_local std::vector<Vec3> b_arcs, a_arcs;
  b_arcs.resize(pb.edges.size());
  for (std::size_t j = 0; j < pb.edges.size(); ++j) {
    const Vec3 w1 = -b_normals[pb.edges[j].left];
    const Vec3 w2 = -b_normals[pb.edges[j].right];
    b_arcs[j] = w2.cross(w1);
  }

  // The Gauss-map test of a pair of edges reads four dot products, each between a face normal of
  // one polyhedron and an arc of the other's edge: computed once per (face, edge) here instead
  // of once per pair of edges (faces are fewer than edges), with the same operands, so the same
  // bits.
  const std::size_t a_edge_count = pa.edges.size(), b_edge_count = pb.edges.size();
  a_arcs.resize(a_edge_count);
  for (std::size_t i = 0; i < a_edge_count; ++i)
    a_arcs[i] = pa.faces[pa.edges[i].right].normal.cross(pa.faces[pa.edges[i].left].normal);
  // b_side[i * |F_B| + f]: B's negated normal f against A's arc i; a_side[f * |E_B| + j]: A's
  // normal f against B's arc j (laid out so that the loop over B's edges reads short rows).
  thread_local std::vector<double> b_side, a_side;
  b_side.resize(pb.faces.size() * a_edge_count);
  a_side.resize(pa.faces.size() * b_edge_count);
  const std::size_t b_face_count = pb.faces.size();
  for (std::size_t f = 0; f < b_face_count; ++f) {
    const Vec3 w = -b_normals[f];
    for (std::size_t i = 0; i < a_edge_count; ++i)
      b_side[i * b_face_count + f] = w.dot(a_arcs[i]);
  }
  for (std::size_t f = 0; f < pa.faces.size(); ++f)
    for (std::size_t j = 0; j < b_edge_count; ++j)
      a_side[f * b_edge_count + j] = pa.faces[f].normal.dot(b_arcs[j]);

  EdgeQuery best;
  for (std::uint32_t i = 0; i < a_edge_count; ++i) {
    const auto& ea = pa.edges[i];
    const Vec3 tail_a = pa.vertices[ea.tail];
    const Vec3 dir_a = pa.vertices[ea.head] - tail_a;
    const double* u1_side = &a_side[ea.left * b_edge_count];
    const double* u2_side = &a_side[ea.right * b_edge_count];
    const double* arc_side = &b_side[i * b_face_count];
    for (std::uint32_t j = 0; j < b_edge_count; ++j) {
      // Do arcs u1-u2 (A) and w1-w2 (B's, negated) cross on the Gauss map?
      const double cba = arc_side[pb.edges[j].left];
      const double dba = arc_side[pb.edges[j].right];
      const double adc = u1_side[j];
      const double bdc = u2_side[j];
      if (!(cba * dba < 0 && adc * bdc < 0 && cba * bdc > 0)) continue;

      const auto& eb = pb.edges[j];
      const Vec3 tail_b = b_vertices[eb.tail];
      const Vec3 dir_b = b_vertices[eb.head] - tail_b;
      Vec3 axis = dir_a.cross(dir_b);
      const double length = axis.norm();
      // Parallel edges make no new axis: the face normals next to them already cover it.
      if (length <= 1e-10 * dir_a.norm() * dir_b.norm()) continue;
      axis /= length;
      if (axis.dot(tail_a - pa.centroid) < 0) axis = -axis;
      const double separation = axis.dot(tail_b - tail_a);
      if (separation > best.separation) {
        best.separation = separation;
        best.edge_a = i;
        best.edge_b = j;
        best.axis = axis;
      }
    }
  }
  best.axis = a.rotation * best.axis;
  return best;
}

}  // namespace tumble
