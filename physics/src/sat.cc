#include "sat.h"

#include <array>
#include <bit>

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
    const Vec3 support = other.box ? other.vertices[box_support_index(-n)] : other.support(-n);
    return n.dot(support) - offset;
  }
  // A box's farthest vertex along d has each coordinate's sign: the general search's answer, or a
  // vertex it ties with (their dot products round to the same value), which gives the same
  // separation.
  static std::uint32_t box_support_index(const Vec3& d) {
    return (d.x() > 0 ? 1u : 0u) | (d.y() > 0 ? 2u : 0u) | (d.z() > 0 ? 4u : 0u);
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

// A's edge i against B's edge j (its ends in A's frame), kept in `best` where it separates more
// than every pair before it. Parallel edges make no new axis: the face normals next to them
// already cover it.
void measure_edge_pair(const ConvexPolyhedron& pa, std::uint32_t i, std::uint32_t j,
                       const Vec3& tail_b, const Vec3& head_b, EdgeQuery* best) {
  Vec3 axis;
  double separation = 0;
  if (!edge_pair_axis(pa, i, tail_b, head_b - tail_b, &axis, &separation)) return;
  if (separation > best->separation) {
    best->separation = separation;
    best->edge_a = i;
    best->edge_b = j;
    best->axis = axis;
  }
}

// Where a box's Gauss map lies (make_box_polyhedron's layout, the same for every box): each
// edge's arc (its right face's normal across its left's) is a unit axis, and its faces' normals
// are unit axes too.
struct BoxEdgeLayout {
  struct Edge {
    int axis;        // the arc: a sign times unit axis `axis`
    int right_axis;  // the right face's normal: a sign times this unit axis
    // The signs the general test's products carry: the two faces' normals' (adc bdc), the arc's
    // and the right face's normal's (cba bdc).
    int faces_sign, arc_right_sign;
  };
  std::array<Edge, 12> edges;
};

int unit_axis(const Vec3& v) {
  int axis = 0;
  v.cwiseAbs().maxCoeff(&axis);
  return axis;
}

const BoxEdgeLayout& box_edge_layout() {
  static const BoxEdgeLayout layout = [] {
    const ConvexPolyhedron box = make_box_polyhedron(Vec3::Ones());
    TUMBLE_ASSERT(box.edges.size() == 12);
    BoxEdgeLayout result;
    for (std::size_t i = 0; i < 12; ++i) {
      const Vec3 left = box.faces[box.edges[i].left].normal;
      const Vec3 right = box.faces[box.edges[i].right].normal;
      const Vec3 arc = right.cross(left);
      BoxEdgeLayout::Edge& edge = result.edges[i];
      edge.axis = unit_axis(arc);
      edge.right_axis = unit_axis(right);
      const int right_sign = right[edge.right_axis] > 0 ? 1 : -1;
      edge.faces_sign = right_sign * (left[unit_axis(left)] > 0 ? 1 : -1);
      edge.arc_right_sign = right_sign * (arc[edge.axis] > 0 ? 1 : -1);
    }
    return result;
  }();
  return layout;
}

// query_edges for two boxes, pair for pair the same answer. The general test reads four dot
// products a pair, each of a face normal of one box with an arc of the other's edge; with a box
// the normal or the arc is a signed unit axis, so each is a signed coordinate of the other's, and
// their products' signs (the test) follow from three tables of coordinate products, which the
// general test rounds the same way (a sign changes no magnitude). Which of B's 12
// edges cross each of A's on the Gauss map is then three bitmasks ANDed, and only those pairs
// (two of each sixteen parallel to one pair of axes) have their axes measured, in the general
// order: the same first largest separation.
EdgeQuery query_box_edges(const PlacedPolyhedron& a, const PlacedPolyhedron& b) {
  const Mat3 rotation = a.rotation.transpose() * b.rotation;
  const Vec3 translation = a.rotation.transpose() * (b.translation - a.translation);
  const ConvexPolyhedron& pa = *a.polyhedron;
  const ConvexPolyhedron& pb = *b.polyhedron;
  std::array<Vec3, 8> b_vertices;
  for (std::size_t v = 0; v < 8; ++v)
    b_vertices[v] = rotation * pb.vertices[v] + translation;
  std::array<Vec3, 6> b_normals;
  for (std::size_t f = 0; f < 6; ++f)
    b_normals[f] = rotation * pb.faces[f].normal;
  // For each of A's axes m (the arcs of A's edges along m): first[m] has bit j where B's edge j's
  // two negated normals have m coordinates of opposite signs; for the other two axes p < q of m,
  // the product of B's arc j's p and q coordinates (`turn`, A's edges' normals against it) and
  // of its left normal's m coordinate with its arc's p or q coordinate (`cross`): each as bits
  // where positive and where negative.
  std::array<std::uint32_t, 3> first{}, turn_positive{}, turn_negative{};
  std::array<std::array<std::uint32_t, 3>, 3> cross_positive{}, cross_negative{};
  for (std::uint32_t j = 0; j < 12; ++j) {
    const ConvexPolyhedron::Edge& eb = pb.edges[j];
    const Vec3 w1 = -b_normals[eb.left];
    const Vec3 w2 = -b_normals[eb.right];
    const Vec3 arc = w2.cross(w1);
    const std::uint32_t bit = 1u << j;
    for (int m = 0; m < 3; ++m) {
      if (w1[m] * w2[m] < 0) first[m] |= bit;
      const int p = m == 0 ? 1 : 0, q = m == 2 ? 1 : 2;
      const double turn = arc[p] * arc[q];
      if (turn > 0) turn_positive[m] |= bit;
      if (turn < 0) turn_negative[m] |= bit;
      for (const int c : {p, q}) {
        const double cross = w1[m] * arc[c];
        if (cross > 0) cross_positive[m][c] |= bit;
        if (cross < 0) cross_negative[m][c] |= bit;
      }
    }
  }
  const BoxEdgeLayout& layout = box_edge_layout();
  EdgeQuery best;
  for (std::uint32_t i = 0; i < 12; ++i) {
    const BoxEdgeLayout::Edge& e = layout.edges[i];
    const int m = e.axis;
    // The general test: cba dba < 0, adc bdc < 0 and cba bdc > 0, where cba and dba are the
    // arc's sign times w1[m] and w2[m], adc and bdc the faces' signs times arc's coordinates.
    std::uint32_t crossing = first[m] & (e.faces_sign > 0 ? turn_negative[m] : turn_positive[m]);
    crossing &=
        e.arc_right_sign > 0 ? cross_positive[m][e.right_axis] : cross_negative[m][e.right_axis];
    for (; crossing != 0; crossing &= crossing - 1) {
      const std::uint32_t j = static_cast<std::uint32_t>(std::countr_zero(crossing));
      measure_edge_pair(pa, i, j, b_vertices[pb.edges[j].tail], b_vertices[pb.edges[j].head],
                        &best);
    }
  }
  best.axis = a.rotation * best.axis;
  return best;
}

// query_faces for a box's faces against a box, the same answer. A box is symmetric about its
// centre, so a face and the opposite one meet the other box's opposite vertices, and the support
// term of their separations is one product: n . v for the face of normal n (v the vertex farthest
// along -n) is (-n) . (-v), bit for bit. Only the faces' offsets differ, by the sign of n . origin.
FaceQuery query_box_faces(const FacesInOther& frame, const ConvexPolyhedron& faces,
                          const ConvexPolyhedron& other) {
  FaceQuery best;
  for (std::uint32_t axis = 0; axis < 3; ++axis) {
    const ConvexPolyhedron::Face &negative = faces.faces[2 * axis],
                                 &positive = faces.faces[2 * axis + 1];
    const Vec3 n = frame.to_other * positive.normal;
    const double along = n.dot(frame.origin);
    const double support = n.dot(other.vertices[FacesInOther::box_support_index(-n)]);
    // The general order: the negative face first, a later one only where it separates more.
    const double separations[2] = {support - (negative.offset - along),
                                   support - (positive.offset + along)};
    for (std::uint32_t side = 0; side < 2; ++side) {
      if (separations[side] > best.separation) {
        best.separation = separations[side];
        best.face = 2 * axis + side;
      }
    }
  }
  return best;
}

}  // namespace

FaceQuery query_faces(const PlacedPolyhedron& faces, const PlacedPolyhedron& other) {
  const FacesInOther frame(faces, other);
  if (faces.polyhedron->box && other.polyhedron->box)
    return query_box_faces(frame, *faces.polyhedron, *other.polyhedron);
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
  if (a.polyhedron->box && b.polyhedron->box) return query_box_edges(a, b);
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

      measure_edge_pair(pa, i, j, b_vertices[pb.edges[j].tail], b_vertices[pb.edges[j].head],
                        &best);
    }
  }
  best.axis = a.rotation * best.axis;
  return best;
}

}  // namespace tumble
