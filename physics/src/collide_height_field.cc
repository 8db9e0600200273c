// Convex bodies against a heightfield, triangle by triangle and edge by edge.
//
// Faces: a body's vertex (a sphere's or capsule's core end) over a triangle and below its plane,
// or within the margin above, is a contact along the triangle's normal, as on a plane. A body on
// a flat triangulated floor then meets exactly the contacts it meets on the plane: it cannot
// catch on the edges between triangles (the "internal edge" problem of triangle meshes).
//
// Edges: only a convex edge (its neighbour slopes away below the triangle's plane) or a boundary
// edge can touch a body where no face does (a ridge under a box's face, a peak poking into it).
// Each such edge is met as a segment (a capsule of radius 0: the narrow phase's round routines),
// and its normal kept only where the surface can push that way: turned about the edge from one
// triangle's normal no farther than the other's (any way outwards over a boundary edge). Flat
// and concave edges are never met: the faces on either side hold whatever lies there. This is
// the "active edge" scheme of Jolt (Rouwé, JoltPhysics ActiveEdges.h) and of Bullet's
// btAdjustInternalEdgeContacts (Coumans), with the edges' convexity found once when the field is
// built.
//
// Contacts of one body whose normals agree within kSameNormal are one manifold (reduced to four
// points as any other); a body touching several slopes gets one manifold per slope.
#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <vector>

#include "manifold.h"
#include "narrow_phase.h"
#include "physics/height_field.h"
#include "segment.h"

namespace tumble {
namespace {

constexpr double kSameNormal = 1 - 1e-6;  // cosine of 1.4 mrad

struct Cluster {
  Vec3 up;  // out of the terrain, towards the body
  std::vector<ContactPoint> points;
};

// Each thread's room, kept from call to call so that a warmed-up step does not allocate.
struct Scratch {
  std::array<Cluster, kMaxTerrainManifolds> clusters;
  int count = 0;
  double margin = 0;
  double scale = 1;  // m: the pair's size, for telling points apart
};

Scratch& thread_scratch() {
  thread_local Scratch scratch;
  return scratch;
}

Vec3 normal_of(const std::array<Vec3, 3>& v) {
  return (v[1] - v[0]).cross(v[2] - v[0]).normalized();
}

// The manifold of contacts pushing along `up` (or, past kMaxTerrainManifolds, the nearest one).
Cluster& cluster_for(Scratch& s, const Vec3& up) {
  int best = -1;
  double best_dot = -2;
  for (int c = 0; c < s.count; ++c) {
    const double d = s.clusters[c].up.dot(up);
    if (d > best_dot) {
      best_dot = d;
      best = c;
    }
  }
  if (best >= 0 && (best_dot >= kSameNormal || s.count == kMaxTerrainManifolds))
    return s.clusters[best];
  Cluster& cluster = s.clusters[s.count++];
  cluster.up = up;
  cluster.points.clear();
  return cluster;
}

// `on_body` on the body's surface, `on_terrain` on the terrain's; the depth is measured along the
// manifold's normal. Where triangles share what touches (a terrain vertex poking into a box's
// face is a vertex of six triangles; a core end over the shared edge of two level ones), the
// point is kept once: the deeper, with the id it came with first (the lowest triangle's), so
// that it is the same point from step to step.
void add_point(Scratch& s, const Vec3& up, const Vec3& on_body, const Vec3& on_terrain,
               std::uint64_t id, bool shared) {
  Cluster& cluster = cluster_for(s, up);
  const double depth = (on_terrain - on_body).dot(cluster.up);
  // A point merged into a manifold of a slightly other normal can end up past the margin.
  if (depth < -s.margin) return;
  if (shared) {
    const double close = 1e-18 * s.scale * s.scale;
    for (ContactPoint& point : cluster.points) {
      if (point.feature_id != id && (point.point_b - on_terrain).squaredNorm() > close) continue;
      if (depth > point.depth) point = ContactPoint{on_body, on_terrain, depth, point.feature_id};
      return;
    }
  }
  cluster.points.push_back(ContactPoint{on_body, on_terrain, depth, id});
}

// A triangle's own points are told apart from another's by mixing in its index.
std::uint64_t terrain_feature(std::size_t triangle, std::uint64_t id) {
  return id ^ ((static_cast<std::uint64_t>(triangle) + 1) * 0x9E3779B97F4A7C15ull);
}

// The normal an edge contact may have: `up` where it turns about edge e of triangle t from the
// triangle's normal `n` no farther than the neighbour's normal (any way outwards over a boundary
// edge), else the nearer of the two normals. A body lying flat on either slope then keeps its
// contact at the ridge with that slope's normal, as the face rule gives it; rejecting the normal
// instead drops the ridge's support whenever the body tilts a hair past the slope, and the body
// rocks.
Vec3 edge_normal(const HeightField& field, std::size_t t, const std::array<Vec3, 3>& v,
                 const Vec3& n, int e, const Vec3& up) {
  const Vec3 along = (v[(e + 1) % 3] - v[e]).normalized();
  const Vec3 outwards = along.cross(n);
  const double x = up.dot(n), y = up.dot(outwards);
  if (std::hypot(x, y) < 1e-9) return up;  // along the edge: a vertex's normal
  const double angle = std::atan2(y, x);
  if (angle < 0) return n;
  const std::int64_t other = field.neighbour(t, e);
  if (other < 0) return up;
  const Vec3 n2 = normal_of(field.triangle(static_cast<std::size_t>(other)));
  return angle <= std::atan2(n2.dot(outwards), n2.dot(n)) ? up : n2;
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

bool inside_triangle(const std::array<Vec3, 3>& v, const Vec3& n, const Vec3& p) {
  const double twice_area = (v[1] - v[0]).cross(v[2] - v[0]).dot(n);
  for (int e = 0; e < 3; ++e) {
    const Vec3& a = v[e];
    const Vec3& b = v[(e + 1) % 3];
    if ((b - a).cross(p - a).dot(n) < -1e-12 * twice_area) return false;
  }
  return true;
}

// The face rule for a sphere's or capsule's core ends over triangle t.
void round_face_points(Scratch& s, const std::array<Vec3, 3>& v, const Vec3& n,
                       std::span<const Vec3> cores, double radius, double margin) {
  for (std::size_t c = 0; c < cores.size(); ++c) {
    const double height = (cores[c] - v[0]).dot(n);
    if (radius - height < -margin) continue;
    const Vec3 foot = cores[c] - height * n;
    if (!inside_triangle(v, n, foot)) continue;
    add_point(s, n, cores[c] - radius * n, foot, kFeatureRound | c, true);
  }
}

}  // namespace

std::uint32_t collide_height_field(const Shape& a, const Mat3& rotation, const Vec3& translation,
                                   const HeightField& field, const CollisionSettings& settings,
                                   TerrainContacts* out) {
  out->count = 0;
  Scratch& s = thread_scratch();
  s.count = 0;
  const double margin = settings.margin;
  s.margin = margin;
  const Aabb local = a.local_bounds();
  const Vec3 centre = rotation * (0.5 * (local.min + local.max)) + translation;
  const Vec3 half = rotation.cwiseAbs() * (0.5 * local.extent()) + Vec3::Constant(margin);
  const Aabb box{centre - half, centre + half};
  if (box.min.z() > field.max_height()) return kCollisionOk;
  std::uint32_t i0, j0, i1, j1;
  if (!field.cells_under(box, &i0, &j0, &i1, &j1)) return kCollisionOk;
  std::uint32_t flags = kCollisionOk;
  const std::size_t width = i1 - i0 + 1;
  if (width * (j1 - j0 + 1) > kMaxTerrainCells) {
    flags |= kTerrainCellLimit;
    i1 = i0 + static_cast<std::uint32_t>(std::min(width, kMaxTerrainCells)) - 1;
    j1 = j0 + static_cast<std::uint32_t>(kMaxTerrainCells / (i1 - i0 + 1)) - 1;
  }

  const bool round = a.type() == ShapeType::kSphere || a.type() == ShapeType::kCapsule;
  std::array<Vec3, 2> core_ends{translation, translation};
  if (a.type() == ShapeType::kCapsule) {
    const Vec3 axis = rotation.col(2) * a.half_height();
    core_ends = {translation - axis, translation + axis};
  }
  const std::span<const Vec3> cores(core_ends.data(), a.type() == ShapeType::kCapsule ? 2 : 1);
  s.scale = std::max(a.size(), field.def().spacing_x + field.def().spacing_y);
  const Mat3 to_body = rotation.transpose();
  const Aabb body_bounds = local.expanded(margin);

  for (std::uint32_t j = j0; j <= j1; ++j) {
    for (std::uint32_t i = i0; i <= i1; ++i) {
      for (std::uint32_t k = 0; k < 2; ++k) {
        const std::size_t t = 2 * (std::size_t{j} * field.cells_x() + i) + k;
        const std::array<Vec3, 3> v = field.triangle(t);
        if (std::max({v[0].z(), v[1].z(), v[2].z()}) < box.min.z()) continue;
        const Vec3 n = normal_of(v);
        if (round) round_face_points(s, v, n, cores, a.radius(), margin);
        const std::uint8_t active = field.active_edges(t);
        for (int e = 0; e < 3; ++e) {
          // Each edge once: from the lower of its two triangles.
          const std::int64_t other = field.neighbour(t, e);
          if ((active & (1u << e)) == 0 || (other >= 0 && static_cast<std::size_t>(other) < t))
            continue;
          const Vec3& p = v[e];
          const Vec3& q = v[(e + 1) % 3];
          if (std::max(p.z(), q.z()) < box.min.z()) continue;
          const std::uint64_t edge_key = 3 * t + e;
          if (round) {
            const SegmentClosest c = closest_between_segments(p, q, cores.front(), cores.back());
            const Vec3 gap = c.on_second - c.on_first;
            const double distance = gap.norm();
            if (a.radius() - distance < -margin) continue;
            const Vec3 up = edge_normal(field, t, v, n, e, distance > 0 ? Vec3(gap / distance) : n);
            add_point(s, up, c.on_second - a.radius() * up, c.on_first,
                      terrain_feature(edge_key, kFeatureRound), true);
            continue;
          }
          // The edge in the body's frame, against the body: a normal from the edge to the body.
          // An edge that misses the body's own bounds, grown by the margin, cannot touch it.
          const Vec3 p_local = to_body * (p - translation), q_local = to_body * (q - translation);
          if (!segment_meets_box(p_local, q_local, body_bounds)) continue;
          ContactManifold m;
          const bool is_box = a.type() == ShapeType::kBox;
          flags |= collide_round_polyhedron(p_local, q_local, 0.0, *a.polyhedron(), a.size(),
                                            is_box ? &a.half_extents() : nullptr, settings, &m);
          if (m.count == 0) continue;
          manifold_to_world(rotation, translation, &m);
          const Vec3 up = edge_normal(field, t, v, n, e, m.normal);
          for (int c = 0; c < m.count; ++c)
            add_point(s, up, m.points[c].point_b, m.points[c].point_a,
                      terrain_feature(edge_key, m.points[c].feature_id), true);
        }
      }
    }
  }

  if (!round) {
    // Each vertex is over one triangle (the cell its x, y fall in, then the side of the diagonal).
    const HeightFieldDef& def = field.def();
    const double x0 = -0.5 * (def.samples_x - 1) * def.spacing_x;
    const double y0 = -0.5 * (def.samples_y - 1) * def.spacing_y;
    const auto& vertices = a.polyhedron()->vertices;
    for (std::uint32_t index = 0; index < vertices.size(); ++index) {
      const Vec3 x = rotation * vertices[index] + translation;
      const double fx = (x.x() - x0) / def.spacing_x, fy = (x.y() - y0) / def.spacing_y;
      const double ci = std::floor(fx), cj = std::floor(fy);
      if (!(ci >= i0 && ci <= i1 && cj >= j0 && cj <= j1)) continue;
      const auto i = static_cast<std::uint32_t>(ci), j = static_cast<std::uint32_t>(cj);
      const std::uint32_t k = fx - ci >= fy - cj ? 0 : 1;
      const std::array<Vec3, 3> v = field.triangle(2 * (std::size_t{j} * field.cells_x() + i) + k);
      const Vec3 n = normal_of(v);
      const double height = (x - v[0]).dot(n);
      if (height > margin) continue;
      add_point(s, n, x, x - height * n, kFeatureVertex | index, false);
    }
  }

  for (int c = 0; c < s.count; ++c) {
    const Cluster& cluster = s.clusters[c];
    ContactManifold& m = out->manifolds[out->count];
    m.normal = -cluster.up;
    m.depth = -std::numeric_limits<double>::infinity();
    for (const ContactPoint& point : cluster.points)
      m.depth = std::max(m.depth, point.depth);
    reduce_points(cluster.points, m.normal, &m);
    if (m.count > 0) ++out->count;
  }
  return flags;
}

std::uint32_t collide_terrain(const Shape& a, const Pose& pose_a, const Shape& b,
                              const Pose& pose_b, const CollisionSettings& settings,
                              TerrainContacts* out) {
  out->count = 0;
  if (is_static_only(a.type()) && is_static_only(b.type())) return kCollisionOk;
  const bool b_is_terrain = b.type() == ShapeType::kHeightField;
  const Shape& body = b_is_terrain ? a : b;
  const Shape& terrain = b_is_terrain ? b : a;
  const Pose& body_pose = b_is_terrain ? pose_a : pose_b;
  const Pose& terrain_pose = b_is_terrain ? pose_b : pose_a;
  const Mat3 terrain_rotation = terrain_pose.orientation.toRotationMatrix();
  const Mat3 rotation = terrain_rotation.transpose() * body_pose.orientation.toRotationMatrix();
  const Vec3 translation =
      terrain_rotation.transpose() * (body_pose.position - terrain_pose.position);
  const std::uint32_t flags =
      collide_height_field(body, rotation, translation, *terrain.height_field(), settings, out);
  for (int c = 0; c < out->count; ++c) {
    ContactManifold& m = out->manifolds[c];
    manifold_to_world(terrain_rotation, terrain_pose.position, &m);
    if (b_is_terrain) continue;
    m.normal = -m.normal;
    for (int i = 0; i < m.count; ++i)
      std::swap(m.points[i].point_a, m.points[i].point_b);
  }
  return flags;
}

}  // namespace tumble
