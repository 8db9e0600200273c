// Convex bodies against triangles (a heightfield's or a mesh's), triangle by triangle and edge by
// edge.
//
// Faces: a body's vertex (a sphere's or capsule's core end) over a triangle and below its plane,
// or within the margin above, is a contact along the triangle's normal, as on a plane. A body on
// a flat triangulated floor then meets exactly the contacts it meets on the plane: it cannot
// catch on the edges between triangles (the "internal edge" problem of triangle meshes).
//
// Edges: only a convex edge (its neighbour slopes away behind the triangle's plane) or a boundary
// edge can touch a body where no face does (a ridge under a box's face, a peak poking into it).
// Each such edge is met as a segment (a capsule of radius 0: the narrow phase's round routines),
// and its normal kept only where the surface can push that way: turned about the edge from one
// triangle's normal no farther than the other's (any way outwards over a boundary edge). Flat
// and concave edges are never met: the faces on either side hold whatever lies there. A convex
// edge too gentle to be active holds a round core only in the wedge between its triangles'
// normals, where the core's feet fall beyond both (gentle_edge). This is
// the "active edge" scheme of Jolt (Rouwé, JoltPhysics ActiveEdges.h) and of Bullet's
// btAdjustInternalEdgeContacts (Coumans), with the edges' convexity found once when the terrain
// is built.
//
// Contacts of one body whose normals agree within kSameNormal are one manifold (reduced to four
// points as any other); a body touching several slopes gets one manifold per slope.
#include "triangle_contacts.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "manifold.h"
#include "segment.h"

namespace tumble {
namespace {

constexpr double kSameNormal = 1 - 1e-6;  // cosine of 1.4 mrad

// The normal an edge contact may have: `up` where it turns about edge e of triangle v from the
// triangle's normal `n` no farther than the neighbour's normal (any way outwards over a boundary
// edge), else the nearer of the two normals. A body lying flat on either slope then keeps its
// contact at the ridge with that slope's normal, as the face rule gives it; rejecting the normal
// instead drops the ridge's support whenever the body tilts a hair past the slope, and the body
// rocks.
Vec3 edge_normal(const std::array<Vec3, 3>& v, const Vec3& n, int e, const Vec3* n2,
                 const Vec3& up) {
  const Vec3 along = (v[(e + 1) % 3] - v[e]).normalized();
  const Vec3 outwards = along.cross(n);
  const double x = up.dot(n), y = up.dot(outwards);
  if (std::hypot(x, y) < 1e-9) return up;  // along the edge: a vertex's normal
  const double angle = std::atan2(y, x);
  if (angle < 0) return n;
  if (n2 == nullptr) return up;
  return angle <= std::atan2(n2->dot(outwards), n2->dot(n)) ? up : *n2;
}

// Whether segment p..q meets the box (slabs, Kay and Kajiya 1986).
bool segment_meets_box(const Vec3& p, const Vec3& q, const Aabb& box) {
  double enter = 0, leave = 1;
  const Vec3 d = q - p;
  for (int k = 0; k < 3; ++k) {
    if (d[k] == 0) {
      if (p[k] < box.min[k] || p[k] > box.max[k]) return false;
      continue;
    }
    double near = (box.min[k] - p[k]) / d[k], far = (box.max[k] - p[k]) / d[k];
    if (near > far) std::swap(near, far);
    enter = std::max(enter, near);
    leave = std::min(leave, far);
    if (enter > leave) return false;
  }
  return true;
}

}  // namespace

TriangleBody::TriangleBody(const Shape& shape, const Mat3& rotation, const Vec3& translation,
                           double margin)
    : shape(shape),
      rotation(rotation),
      to_body(rotation.transpose()),
      translation(translation),
      round(shape.type() == ShapeType::kSphere || shape.type() == ShapeType::kCapsule),
      core_ends{translation, translation},
      core_count(shape.type() == ShapeType::kCapsule ? 2 : 1) {
  if (shape.type() == ShapeType::kCapsule) {
    const Vec3 axis = rotation.col(2) * shape.half_height();
    core_ends = {translation - axis, translation + axis};
  }
  const Aabb local = shape.local_bounds();
  const Vec3 centre = rotation * (0.5 * (local.min + local.max)) + translation;
  const Vec3 half = rotation.cwiseAbs() * (0.5 * local.extent()) + Vec3::Constant(margin);
  bounds = {centre - half, centre + half};
  body_bounds = local.expanded(margin);
}

TriangleContacts& TriangleContacts::begin(double margin, double scale) {
  thread_local TriangleContacts contacts;
  contacts.count_ = 0;
  contacts.core_held_ = {false, false};
  contacts.margin_ = margin;
  contacts.scale_ = scale;
  return contacts;
}

// The manifold of contacts pushing along `up` (or, past kMaxTerrainManifolds, the nearest one).
TriangleContacts::Cluster& TriangleContacts::cluster_for(const Vec3& up) {
  int best = -1;
  double best_dot = -2;
  for (int c = 0; c < count_; ++c) {
    const double d = clusters_[c].up.dot(up);
    if (d > best_dot) {
      best_dot = d;
      best = c;
    }
  }
  if (best >= 0 && (best_dot >= kSameNormal || count_ == kMaxTerrainManifolds))
    return clusters_[best];
  Cluster& cluster = clusters_[count_++];
  cluster.up = up;
  cluster.points.clear();
  return cluster;
}

// The depth is measured along the manifold's normal. Where triangles share what touches (a
// terrain vertex poking into a box's face is a vertex of six triangles; a core end over the
// shared edge of two level ones), the point is kept once: the deeper, with the id it came with
// first (the lowest triangle's), so that it is the same point from step to step.
void TriangleContacts::add_point(const Vec3& up, const Vec3& on_body, const Vec3& on_terrain,
                                 std::uint64_t id, bool shared) {
  Cluster& cluster = cluster_for(up);
  const double depth = (on_terrain - on_body).dot(cluster.up);
  // A point merged into a manifold of a slightly other normal can end up past the margin.
  if (depth < -margin_) return;
  if (shared) {
    const double close = 1e-18 * scale_ * scale_;
    for (ContactPoint& point : cluster.points) {
      if (point.feature_id != id && (point.point_b - on_terrain).squaredNorm() > close) continue;
      if (depth > point.depth) point = ContactPoint{on_body, on_terrain, depth, point.feature_id};
      return;
    }
  }
  cluster.points.push_back(ContactPoint{on_body, on_terrain, depth, id});
}

bool inside_triangle(const std::array<Vec3, 3>& v, const Vec3& n, const Vec3& p) {
  const double twice_area = (v[1] - v[0]).cross(v[2] - v[0]).dot(n);
  for (int e = 0; e < 3; ++e) {
    const Vec3& a = v[e];
    const Vec3& b = v[(e + 1) % 3];
    if ((b - a).cross(p - a).dot(n) < -1e-12 * twice_area) return false;
  }
  return true;
}

void TriangleContacts::round_face_points(const TriangleBody& body, const std::array<Vec3, 3>& v,
                                         const Vec3& n) {
  const double radius = body.shape.radius();
  for (int c = 0; c < body.core_count; ++c) {
    const Vec3& core = body.core_ends[c];
    const double height = (core - v[0]).dot(n);
    if (radius - height < -margin_) continue;
    const Vec3 foot = core - height * n;
    if (!inside_triangle(v, n, foot)) continue;
    core_held_[c] = true;
    add_point(n, core - radius * n, foot, kFeatureRound | c, true);
  }
}

void TriangleContacts::vertex_face_point(const std::array<Vec3, 3>& v, const Vec3& n, const Vec3& x,
                                         std::uint32_t index, bool shared) {
  const double height = (x - v[0]).dot(n);
  if (height > margin_) return;
  add_point(n, x, x - height * n, kFeatureVertex | index, shared);
}

std::uint32_t TriangleContacts::edge(const TriangleBody& body, const std::array<Vec3, 3>& v,
                                     const Vec3& n, int e, const Vec3* neighbour_normal,
                                     std::uint64_t edge_key, const CollisionSettings& settings) {
  const Vec3& p = v[e];
  const Vec3& q = v[(e + 1) % 3];
  if (body.round) {
    const double radius = body.shape.radius();
    const SegmentClosest c =
        closest_between_segments(p, q, body.core_ends[0], body.core_ends[body.core_count - 1]);
    const Vec3 gap = c.on_second - c.on_first;
    const double distance = gap.norm();
    if (radius - distance < -margin_) return kCollisionOk;
    const Vec3 along_gap = distance > 0 ? Vec3(gap / distance) : n;
    const Vec3 up = edge_normal(v, n, e, neighbour_normal, along_gap);
    // Along a clamped normal the pair's offset is not their gap: a core beside an edge a metre
    // off (continuous collision's sweeps ask with such margins) is level with it along the
    // face's normal, and read as touching it, and the sweep let a ball at 100 m/s through the
    // hills. The gap along the clamped normal is the distance.
    const Vec3 on_terrain = up == along_gap ? c.on_first : Vec3(c.on_second - distance * up);
    add_point(up, c.on_second - radius * up, on_terrain, terrain_feature(edge_key, kFeatureRound),
              true);
    return kCollisionOk;
  }
  // The edge in the body's frame, against the body: a normal from the edge to the body. An edge
  // that misses the body's own bounds, grown by the margin, cannot touch it.
  const Vec3 p_local = body.to_body * (p - body.translation);
  const Vec3 q_local = body.to_body * (q - body.translation);
  if (!segment_meets_box(p_local, q_local, body.body_bounds)) return kCollisionOk;
  ContactManifold m;
  const bool is_box = body.shape.type() == ShapeType::kBox;
  const std::uint32_t flags =
      collide_round_polyhedron(p_local, q_local, 0.0, *body.shape.polyhedron(), body.shape.size(),
                               is_box ? &body.shape.half_extents() : nullptr, settings, &m);
  if (m.count == 0) return flags;
  manifold_to_world(body.rotation, body.translation, &m);
  const Vec3 up = edge_normal(v, n, e, neighbour_normal, m.normal);
  // As for a round core above: along a clamped normal the gap is the pair's distance (its depth
  // along their own normal), not the points' offset along it.
  for (int c = 0; c < m.count; ++c) {
    const ContactPoint& point = m.points[c];
    const Vec3 on_terrain = up == m.normal ? point.point_a : Vec3(point.point_b + point.depth * up);
    add_point(up, point.point_b, on_terrain, terrain_feature(edge_key, point.feature_id), true);
  }
  return flags;
}

void TriangleContacts::gentle_edge(const TriangleBody& body, const std::array<Vec3, 3>& v,
                                   const Vec3& n, int e, const Vec3& neighbour_normal,
                                   std::uint64_t edge_key) {
  const Vec3& p = v[e];
  const Vec3& q = v[(e + 1) % 3];
  const double radius = body.shape.radius();
  const double reach = radius + margin_;
  const Vec3 along = q - p;
  // The wedge: turned from n towards the outside of the edge, short of the neighbour's normal
  // (which turns the same way by at most kSmoothEdgeAngle). Each bound is a plane through the
  // edge (normals n, `outwards`, `short_of`, none along it), so a point's side of each is its
  // offset from p along the normal, whatever point of the edge it is nearest.
  const Vec3 outwards = along.cross(n);
  const Vec3 short_of = neighbour_normal.dot(outwards) * n - neighbour_normal.dot(n) * outwards;
  const auto in_wedge = [&](const Vec3& d) {
    return d.dot(n) > 0 && d.dot(outwards) > 0 && d.dot(short_of) > 0;
  };
  const auto meet = [&](const Vec3& core, const Vec3& on_edge, std::uint64_t id) {
    const Vec3 gap = core - on_edge;
    if (gap.squaredNorm() > reach * reach) return;
    const Vec3 up = gap.normalized();
    add_point(up, core - radius * up, on_edge, terrain_feature(edge_key, id), true);
  };
  for (int c = 0; c < body.core_count; ++c) {
    const Vec3& core = body.core_ends[c];
    if (core_held_[c] || !in_wedge(core - p)) continue;
    const double t = std::clamp((core - p).dot(along) / along.squaredNorm(), 0.0, 1.0);
    meet(core, p + t * along, kFeatureRound | c);
  }
}

void TriangleContacts::finish(TerrainContacts* out) {
  out->count = 0;
  for (int c = 0; c < count_; ++c) {
    const Cluster& cluster = clusters_[c];
    ContactManifold& m = out->manifolds[out->count];
    m.normal = -cluster.up;
    m.depth = -std::numeric_limits<double>::infinity();
    for (const ContactPoint& point : cluster.points)
      m.depth = std::max(m.depth, point.depth);
    reduce_points(cluster.points, m.normal, &m);
    if (m.count > 0) ++out->count;
  }
}

}  // namespace tumble
