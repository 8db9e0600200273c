// Support-function adaptors. GJK and EPA see a shape only through `Vec3 support(const Vec3& d)`,
// the point of the shape farthest along d, all in one common frame (body A's).
#pragma once

#include "physics/math.h"
#include "physics/polyhedron.h"

namespace tumble {

template <class T>
concept SupportShape = requires(const T& shape, const Vec3& d) {
  { shape.support(d) } -> std::convertible_to<Vec3>;
};

struct PointSupport {
  Vec3 point;
  Vec3 support(const Vec3&) const { return point; }
};

struct SegmentSupport {
  Vec3 p, q;
  Vec3 support(const Vec3& d) const { return d.dot(q - p) > 0 ? q : p; }
};

struct BoxSupport {
  Vec3 half;
  Vec3 support(const Vec3& d) const {
    return Vec3(d.x() >= 0 ? half.x() : -half.x(), d.y() >= 0 ? half.y() : -half.y(),
                d.z() >= 0 ? half.z() : -half.z());
  }
};

struct PolyhedronSupport {
  const ConvexPolyhedron* polyhedron;
  Vec3 support(const Vec3& d) const { return polyhedron->support(d); }
};

struct SphereSupport {
  Vec3 centre;
  double radius;
  Vec3 support(const Vec3& d) const {
    const double n = d.norm();
    return n > 0 ? Vec3(centre + d * (radius / n)) : Vec3(centre + Vec3(radius, 0, 0));
  }
};

// A shape seen from another frame: x = rotation * local + translation.
template <SupportShape S>
struct Transformed {
  const S& shape;
  Mat3 rotation;
  Vec3 translation;
  Vec3 support(const Vec3& d) const {
    return rotation * shape.support(rotation.transpose() * d) + translation;
  }
};

}  // namespace tumble
