#include "ray_shape.h"

#include "physics/compound.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace tumble {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// The ray's entry into the sphere of `radius` about `centre`: the smaller root of
// |o + t d - c|^2 = r^2 (d unit), written to avoid cancellation (Numerical Recipes 5.6).
bool ray_sphere(const Vec3& centre, double radius, const Vec3& origin, const Vec3& direction,
                double max_t, ShapeRayHit* hit) {
  const Vec3 m = origin - centre;
  const double c = m.squaredNorm() - radius * radius;
  if (c <= 0) {
    hit->t = 0;
    hit->normal = -direction;
    return true;
  }
  const double b = m.dot(direction);
  if (b >= 0) return false;  // outside and moving away
  const double discriminant = b * b - c;
  if (discriminant < 0) return false;
  // Roots -b -+ sqrt(disc); the nearer is c / (-b + sqrt(disc)) without cancellation.
  const double t = c / (-b + std::sqrt(discriminant));
  if (t > max_t) return false;
  hit->t = t;
  hit->normal = (m + t * direction) / radius;
  hit->normal.normalize();
  return true;
}

// Slabs (Kay and Kajiya 1986): the latest entry over the three axes before the earliest exit.
bool ray_box(const Vec3& half, const Vec3& origin, const Vec3& direction, double max_t,
             ShapeRayHit* hit) {
  double enter = -kInfinity, leave = kInfinity;
  int enter_axis = -1;
  for (int k = 0; k < 3; ++k) {
    if (direction[k] == 0) {
      if (std::abs(origin[k]) > half[k]) return false;
      continue;
    }
    const double inverse = 1 / direction[k];
    double near = (-half[k] - origin[k]) * inverse, far = (half[k] - origin[k]) * inverse;
    if (near > far) std::swap(near, far);
    if (near > enter) {
      enter = near;
      enter_axis = k;
    }
    leave = std::min(leave, far);
  }
  if (enter > leave || leave < 0) return false;
  if (enter <= 0) {  // the origin is inside
    hit->t = 0;
    hit->normal = -direction;
    return true;
  }
  if (enter > max_t) return false;
  hit->t = enter;
  hit->normal = Vec3::Zero();
  hit->normal[enter_axis] = direction[enter_axis] > 0 ? -1 : 1;
  return true;
}

// A capsule: the cylinder about z between the caps' centres, and the two end spheres.
bool ray_capsule(double radius, double half_height, const Vec3& origin, const Vec3& direction,
                 double max_t, ShapeRayHit* hit) {
  // Inside: nearer to the core segment than the radius.
  const Vec3 nearest_on_core(0, 0, std::clamp(origin.z(), -half_height, half_height));
  if ((origin - nearest_on_core).squaredNorm() <= radius * radius) {
    hit->t = 0;
    hit->normal = -direction;
    return true;
  }
  bool found = false;
  ShapeRayHit best;
  best.t = kInfinity;
  // The side: |(o + t d)_xy|^2 = r^2 with z within the core.
  const double a = direction.x() * direction.x() + direction.y() * direction.y();
  if (a > 0) {
    const double b = origin.x() * direction.x() + origin.y() * direction.y();
    const double c = origin.x() * origin.x() + origin.y() * origin.y() - radius * radius;
    const double discriminant = b * b - a * c;
    if (discriminant >= 0 && b < 0) {
      const double t = c / (-b + std::sqrt(discriminant));  // the nearer root (c > 0 here)
      const double z = origin.z() + t * direction.z();
      if (t >= 0 && t <= max_t && std::abs(z) <= half_height) {
        best.t = t;
        best.normal = Vec3(origin.x() + t * direction.x(), origin.y() + t * direction.y(), 0);
        best.normal.normalize();
        found = true;
      }
    }
  }
  for (const double end : {-half_height, half_height}) {
    ShapeRayHit cap;
    if (ray_sphere(Vec3(0, 0, end), radius, origin, direction, std::min(max_t, best.t), &cap) &&
        cap.t < best.t) {
      best = cap;
      found = true;
    }
  }
  if (found) *hit = best;
  return found;
}

// Cyrus-Beck: the ray clipped by each face's half-space; it enters through the face whose
// plane it crosses last on the way in.
bool ray_hull(const ConvexPolyhedron& hull, const Vec3& origin, const Vec3& direction,
              double max_t, ShapeRayHit* hit) {
  double enter = 0, leave = max_t;
  const ConvexPolyhedron::Face* entry = nullptr;
  for (const ConvexPolyhedron::Face& face : hull.faces) {
    const double height = face.normal.dot(origin) - face.offset;  // > 0: outside this plane
    const double rate = face.normal.dot(direction);
    if (rate == 0) {
      if (height > 0) return false;
      continue;
    }
    const double t = -height / rate;
    if (rate < 0) {
      if (t > enter) {
        enter = t;
        entry = &face;
      }
    } else {
      leave = std::min(leave, t);
    }
    if (enter > leave) return false;
  }
  hit->t = enter;
  hit->normal = entry == nullptr ? Vec3(-direction) : entry->normal;
  return true;
}

// Whether the ray meets the box within [0, max_t] (the slab test, Kay and Kajiya 1986).
bool ray_meets_box(const Aabb& box, const Vec3& origin, const Vec3& direction, double max_t) {
  double enter = 0, leave = max_t;
  for (int k = 0; k < 3; ++k) {
    if (direction[k] == 0) {
      if (origin[k] < box.min[k] || origin[k] > box.max[k]) return false;
      continue;
    }
    const double inverse = 1 / direction[k];
    double near = (box.min[k] - origin[k]) * inverse, far = (box.max[k] - origin[k]) * inverse;
    if (near > far) std::swap(near, far);
    enter = std::max(enter, near);
    leave = std::min(leave, far);
    if (enter > leave) return false;
  }
  return true;
}

// The nearest entry into any part, each met in its own frame.
bool ray_compound(const Compound& compound, const Vec3& origin, const Vec3& direction, double max_t,
                  ShapeRayHit* hit) {
  bool found = false;
  double reach = max_t;
  for (const Compound::Part& part : compound.parts()) {
    if (!ray_meets_box(part.bounds, origin, direction, reach)) continue;
    const Quat into = part.pose.orientation.conjugate();
    ShapeRayHit part_hit;
    if (!ray_shape(part.shape, into * (origin - part.pose.position), into * direction, reach,
                   &part_hit))
      continue;
    if (found && part_hit.t >= hit->t) continue;
    found = true;
    hit->t = part_hit.t;
    hit->normal = part.pose.orientation * part_hit.normal;
    reach = part_hit.t;
  }
  return found;
}

}  // namespace

bool ray_shape(const Shape& shape, const Vec3& origin, const Vec3& direction, double max_t,
               ShapeRayHit* hit) {
  switch (shape.type()) {
    case ShapeType::kSphere:
      return ray_sphere(Vec3::Zero(), shape.radius(), origin, direction, max_t, hit);
    case ShapeType::kCapsule:
      return ray_capsule(shape.radius(), shape.half_height(), origin, direction, max_t, hit);
    case ShapeType::kBox:
      return ray_box(shape.half_extents(), origin, direction, max_t, hit);
    case ShapeType::kHull:
      return ray_hull(*shape.polyhedron(), origin, direction, max_t, hit);
    case ShapeType::kHeightField:
      return ray_height_field(*shape.height_field(), origin, direction, max_t, hit);
    case ShapeType::kMesh:
      return ray_mesh(*shape.mesh(), origin, direction, max_t, hit);
    case ShapeType::kCompound:
      return ray_compound(*shape.compound(), origin, direction, max_t, hit);
    case ShapeType::kHalfSpace: {
      // The solid below z = 0.
      if (origin.z() <= 0) {
        hit->t = 0;
        hit->normal = -direction;
        return true;
      }
      if (direction.z() >= 0) return false;
      const double t = -origin.z() / direction.z();
      if (t > max_t) return false;
      hit->t = t;
      hit->normal = Vec3::UnitZ();
      return true;
    }
  }
  return false;
}

}  // namespace tumble
