#include "sat.h"

namespace tumble {

namespace {

// Faces are measured in `other`'s local frame: the support query is then a plain loop over its
// vertices.
struct FacesInOther {
  Mat3 to_other;
  Vec3 origin;
  FacesInOther(const PlacedPolyhedron& faces, const PlacedPolyhedron& other)
      : to_other(other.rotation.transpose() * faces.rotation),
        origin(other.rotation.transpose() * (faces.translation - other.translation)) {}
  double separation(const ConvexPolyhedron::Face& face, const ConvexPolyhedron& other) const {
    const Vec3 n = to_other * face.normal;
    const double offset = face.offset + n.dot(origin);
    return n.dot(other.support(-n)) - offset;
  }
};

// The axis of one pair of edges in A's frame (B placed there by rotation, translation), from A
// towards B, and the separation along it; false for parallel edges, which make no axis.
bool edge_pair_axis(const ConvexPolyhedron& pa, std::uint32_t i, const Vec3& tail_b,
                    const Vec3& dir_b, Vec3* axis, double* separation) {
  const auto& ea = pa.edges[i];
  const Vec3 tail_a = pa.vertices[ea.tail];
  const Vec3 dir_a = pa.vertices[ea.head] - tail_a;
  *axis = dir_a.cross(dir_b);
  const double length = axis->norm();
  if (length <= 1e-10 * dir_a.norm() * dir_b.norm()) return false;
  *axis /= length;
  if (axis->dot(tail_a - pa.centroid) < 0) *axis = -*axis;
  *separation = axis->dot(tail_b - tail_a);
  return true;
}

}  // namespace

FaceQuery query_faces(const PlacedPolyhedron& faces, const PlacedPolyhedron& other) {
  const FacesInOther frame(faces, other);
  FaceQuery best;
  const auto& list = faces.polyhedron->faces;
  for (std::uint32_t f = 0; f < list.size(); ++f) {
    const double separation = frame.separation(list[f], *other.polyhedron);
    if (separation > best.separation) {
      best.separation = separation;
      best.face = f;
    }
  }
  return best;
}

FaceQuery query_face(const PlacedPolyhedron& faces, std::uint32_t face,
                     const PlacedPolyhedron& other) {
  return {face,
          FacesInOther(faces, other).separation(faces.polyhedron->faces[face], *other.polyhedron)};
}

EdgeQuery query_edge_pair(const PlacedPolyhedron& a, std::uint32_t edge_a,
                          const PlacedPolyhedron& b, std::uint32_t edge_b) {
  const Mat3 rotation = a.rotation.transpose() * b.rotation;
  const Vec3 translation = a.rotation.transpose() * (b.translation - a.translation);
  const auto& eb = b.polyhedron->edges[edge_b];
  const Vec3 tail_b = rotation * b.polyhedron->vertices[eb.tail] + translation;
  const Vec3 dir_b = (rotation * b.polyhedron->vertices[eb.head] + translation) - tail_b;
  EdgeQuery query;
  Vec3 axis;
  double separation = 0;
  if (!edge_pair_axis(*a.polyhedron, edge_a, tail_b, dir_b, &axis, &separation)) return query;
  query.edge_a = edge_a;
  query.edge_b = edge_b;
  query.separation = separation;
  query.axis = a.rotation * axis;
  return query;
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
      Vec3 axis;
      double separation = 0;
      // Parallel edges make no new axis: the face normals next to them already cover it.
      if (!edge_pair_axis(pa, i, tail_b, dir_b, &axis, &separation)) continue;
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
