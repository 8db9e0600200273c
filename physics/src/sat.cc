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
  // B's Gauss-map arcs, negated for the Minkowski difference A - B: the same for every edge of A.
  struct Arc {
    Vec3 w1, w2, w2xw1;
  };
  thread_local std::vector<Arc> b_arcs;
  b_arcs.resize(pb.edges.size());
  for (std::size_t j = 0; j < pb.edges.size(); ++j) {
    Arc& arc = b_arcs[j];
    arc.w1 = -b_normals[pb.edges[j].left];
    arc.w2 = -b_normals[pb.edges[j].right];
    arc.w2xw1 = arc.w2.cross(arc.w1);
  }

  EdgeQuery best;
  for (std::uint32_t i = 0; i < pa.edges.size(); ++i) {
    const auto& ea = pa.edges[i];
    const Vec3& u1 = pa.faces[ea.left].normal;
    const Vec3& u2 = pa.faces[ea.right].normal;
    const Vec3 tail_a = pa.vertices[ea.tail];
    const Vec3 dir_a = pa.vertices[ea.head] - tail_a;
    const Vec3 u2xu1 = u2.cross(u1);
    for (std::uint32_t j = 0; j < pb.edges.size(); ++j) {
      // Do arcs u1-u2 (A) and w1-w2 (B's, negated) cross on the Gauss map?
      const Arc& arc = b_arcs[j];
      const double cba = arc.w1.dot(u2xu1);
      const double dba = arc.w2.dot(u2xu1);
      const double adc = u1.dot(arc.w2xw1);
      const double bdc = u2.dot(arc.w2xw1);
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
