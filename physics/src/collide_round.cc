// Spheres and capsules: a point or a segment (the core) swept by a radius. Against each other the
// answer is closed-form (closest points of the cores); against a polytope the core's distance comes
// from GJK, and a core that has entered the polytope from EPA (segment) or the face planes (point);
// against a box both are closed-form (segment.h).
#include "epa.h"
#include "manifold.h"
#include "narrow_phase.h"
#include "segment.h"

namespace tumble {
namespace {

// Writes a one-point manifold from the two surface points, both in one frame.
void single_point(const Vec3& normal, const Vec3& surface_a, const Vec3& surface_b, double depth,
                  std::uint64_t id, ContactManifold* out) {
  out->normal = normal;
  out->depth = depth;
  out->count = 1;
  out->points[0] = {surface_a, surface_b, depth, id};
}

// A unit direction from `from` to `to`, or `fallback` when they coincide.
Vec3 direction_or(const Vec3& from, const Vec3& to, const Vec3& fallback, double* distance) {
  const Vec3 d = to - from;
  *distance = d.norm();
  return *distance > 0 ? Vec3(d / *distance) : fallback;
}

}  // namespace

std::uint32_t collide_sphere_sphere(double radius_a, double radius_b, const Vec3& centre_b,
                                    double margin, ContactManifold* out) {
  out->count = 0;
  double distance;
  const Vec3 n = direction_or(Vec3::Zero(), centre_b, Vec3::UnitZ(), &distance);
  const double depth = radius_a + radius_b - distance;
  if (depth < -margin) return kCollisionOk;
  single_point(n, radius_a * n, centre_b - radius_b * n, depth, kFeatureRound, out);
  return kCollisionOk;
}

std::uint32_t collide_sphere_capsule(double radius_a, const Shape& capsule_b, const Mat3& rotation,
                                     const Vec3& translation, double margin, ContactManifold* out) {
  out->count = 0;
  const Vec3 axis = rotation.col(2) * capsule_b.half_height();
  const Vec3 p = translation - axis, q = translation + axis;
  const Vec3 nearest = p + closest_on_segment(p, q, Vec3::Zero()) * (q - p);
  double distance;
  const Vec3 n = direction_or(Vec3::Zero(), nearest, any_orthogonal(axis), &distance);
  const double depth = radius_a + capsule_b.radius() - distance;
  if (depth < -margin) return kCollisionOk;
  single_point(n, radius_a * n, nearest - capsule_b.radius() * n, depth, kFeatureRound, out);
  return kCollisionOk;
}

std::uint32_t collide_capsules(const Shape& a, const Shape& b, const Mat3& rotation,
                               const Vec3& translation, double margin, ContactManifold* out) {
  out->count = 0;
  const Vec3 pa(0, 0, -a.half_height()), qa(0, 0, a.half_height());
  const Vec3 axis_b = rotation.col(2) * b.half_height();
  const Vec3 pb = translation - axis_b, qb = translation + axis_b;
  const SegmentClosest c = closest_between_segments(pa, qa, pb, qb);
  const double radii = a.radius() + b.radius();
  double distance;
  Vec3 fallback = Vec3::UnitZ().cross(axis_b);
  fallback = fallback.squaredNorm() > 0 ? fallback.normalized() : Vec3::UnitX();
  if (fallback.dot(translation) < 0) fallback = -fallback;
  const Vec3 n = direction_or(c.on_first, c.on_second, fallback, &distance);
  if (radii - distance < -margin) return kCollisionOk;

  // Parallel capsules lying side by side touch along a line: two points at the overlap's ends.
  const Vec3 dir_b = axis_b.normalized();
  if (std::abs(dir_b.z()) > 1 - 1e-6) {
    const double lo = std::max(-a.half_height(), std::min(pb.z(), qb.z()));
    const double hi = std::min(a.half_height(), std::max(pb.z(), qb.z()));
    if (hi > lo) {
      out->normal = n;
      out->depth = radii - distance;
      out->count = 0;
      for (double z : {lo, hi}) {
        const Vec3 on_a(0, 0, z);
        const Vec3 on_b = pb + closest_on_segment(pb, qb, on_a) * (qb - pb);
        const double depth = radii - n.dot(on_b - on_a);
        if (depth < -margin) continue;
        out->points[out->count] = {on_a + a.radius() * n, on_b - b.radius() * n, depth,
                                   kFeatureRound | static_cast<std::uint64_t>(out->count)};
        ++out->count;
      }
      return kCollisionOk;
    }
  }
  single_point(n, c.on_first + a.radius() * n, c.on_second - b.radius() * n, radii - distance,
               kFeatureRound, out);
  return kCollisionOk;
}

std::uint32_t collide_round_polytope(const Vec3& p, const Vec3& q, double radius,
                                     const Shape& polytope_b, const CollisionSettings& settings,
                                     ContactManifold* out) {
  const bool box = polytope_b.type() == ShapeType::kBox;
  return collide_round_polyhedron(p, q, radius, *polytope_b.polyhedron(), polytope_b.size(),
                                  box ? &polytope_b.half_extents() : nullptr, settings, out);
}

std::uint32_t collide_round_polyhedron(const Vec3& p, const Vec3& q, double radius,
                                       const ConvexPolyhedron& poly, double size,
                                       const Vec3* box_half_extents,
                                       const CollisionSettings& settings, ContactManifold* out) {
  out->count = 0;
  const double margin = settings.margin;
  const double tolerance = 1e-12 * (size + radius + (q - p).norm());
  const bool is_point = p == q;
  std::uint32_t flags = kCollisionOk;
  Vec3 normal;        // A to B
  Vec3 core_point;    // deepest point of A's core
  double core_depth;  // how far the core reaches into B (negative: its distance from B)

  if (is_point && box_half_extents != nullptr) {
    // Closed form: clamp to the box, or push out through the nearest face from inside.
    const Vec3& h = *box_half_extents;
    const Vec3 clamped = p.cwiseMax(-h).cwiseMin(h);
    if (clamped != p) {
      double distance;
      normal = direction_or(p, clamped, Vec3::UnitZ(), &distance);
      core_depth = -distance;
    } else {
      const Vec3 room = h - p.cwiseAbs();
      int axis = 0;
      core_depth = room.minCoeff(&axis);
      normal = Vec3::Zero();
      normal[axis] = p[axis] >= 0 ? -1.0 : 1.0;
    }
    core_point = p;
  } else if (const SegmentBoxClosest closest = box_half_extents != nullptr
                                                   ? closest_segment_box(p, q, *box_half_extents)
                                                   : SegmentBoxClosest{0, 0};
             closest.squared_distance > tolerance * tolerance) {
    // Apart from a box: its closest points in closed form (segment.h).
    core_point = p + closest.t * (q - p);
    const Vec3 on_box = core_point.cwiseMax(-*box_half_extents).cwiseMin(*box_half_extents);
    normal = direction_or(core_point, on_box, Vec3::UnitZ(), &core_depth);
    core_depth = -core_depth;
  } else if (box_half_extents != nullptr) {
    // Into a box: the shortest way out in closed form too (segment.h).
    const SegmentBoxPenetration out = segment_box_penetration(p, q, *box_half_extents, tolerance);
    normal = out.normal;
    core_depth = out.depth;
    core_point = out.deepest;
  } else {
    const SegmentSupport core{p, q};
    const PolyhedronSupport support_b{&poly};
    GjkSettings gjk_settings;
    gjk_settings.tolerance = tolerance;
    const GjkResult gjk = gjk_distance(core, support_b, p - poly.centroid, gjk_settings);
    if (gjk.status == GjkStatus::kIterationLimit) flags |= kGjkIterationLimit;
    if (gjk.status != GjkStatus::kIntersecting && gjk.distance > tolerance) {
      normal = (gjk.point_b - gjk.point_a) / gjk.distance;
      core_depth = -gjk.distance;
      core_point = gjk.point_a;
    } else if (is_point) {
      // A point inside a polytope leaves through the face plane nearest to it.
      core_depth = std::numeric_limits<double>::infinity();
      for (const auto& face : poly.faces) {
        const double room = face.offset - face.normal.dot(p);
        if (room < core_depth) {
          core_depth = room;
          normal = -face.normal;
        }
      }
      core_point = p;
    } else {
      EpaSettings epa_settings;
      epa_settings.tolerance = tolerance;
      const EpaResult epa = epa_penetration(core, support_b, gjk.simplex, epa_settings);
      if (epa.status == EpaStatus::kIterationLimit) flags |= kEpaIterationLimit;
      if (epa.status == EpaStatus::kDegenerate) flags |= kEpaDegenerate;
      normal = epa.normal;
      core_depth = epa.depth;
      core_point = epa.point_a;
    }
  }
  const double depth = core_depth + radius;
  if (depth < -margin) return flags;

  // A capsule lying flat on a face touches it along a segment: clip the core to the face.
  if (!is_point) {
    const PlacedPolyhedron placed{&poly, Mat3::Identity(), Vec3::Zero()};
    const std::uint32_t f = most_opposed_face(placed, normal);
    const auto& face = poly.faces[f];
    const Vec3 axis = (q - p).normalized();
    if (-face.normal.dot(normal) > 1 - 1e-6 && std::abs(axis.dot(face.normal)) < 1e-3) {
      double t0 = 0, t1 = 1;
      for (std::uint32_t k = 0; k < face.count; ++k) {
        const Vec3 v0 = poly.face_vertex(face, k), v1 = poly.face_vertex(face, k + 1);
        const Vec3 side = (v1 - v0).cross(face.normal);
        const double dp = side.dot(p - v0), dq = side.dot(q - v0);
        if (dp > 0 && dq > 0)
          t1 = -1;  // wholly outside this side
        else if (dp > 0)
          t0 = std::max(t0, dp / (dp - dq));
        else if (dq > 0)
          t1 = std::min(t1, dp / (dp - dq));
      }
      if (t1 > t0) {
        out->normal = -face.normal;
        out->depth = depth;
        out->count = 0;
        for (double t : {t0, t1}) {
          const Vec3 x = p + t * (q - p);
          const double gap = face.normal.dot(x) - face.offset;
          const double point_depth = radius - gap;
          if (point_depth < -margin) continue;
          out->points[out->count] = {x + radius * out->normal, x - gap * face.normal, point_depth,
                                     feature_id(kFeatureRound, f, out->count, 1)};
          ++out->count;
        }
        if (out->count > 0) return flags;
      }
    }
  }
  single_point(normal, core_point + radius * normal, core_point - core_depth * normal, depth,
               kFeatureRound, out);
  return flags;
}

}  // namespace tumble
