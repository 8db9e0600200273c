// Vector types, rigid transforms and bounding boxes shared by the whole engine.
// Everything is double precision, SI units, z up.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

namespace tumble {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Quaterniond;

inline bool is_finite(double x) {
  return std::isfinite(x);
}
inline bool is_finite(const Vec3& v) {
  return v.allFinite();
}
inline bool is_finite(const Quat& q) {
  return q.coeffs().allFinite();
}

// A rigid transform from a local frame to the world: world = rotation * local + position.
struct Pose {
  Vec3 position = Vec3::Zero();
  Quat orientation = Quat::Identity();

  Vec3 transform(const Vec3& local) const { return orientation * local + position; }
  Vec3 inverse_transform(const Vec3& world) const {
    return orientation.conjugate() * (world - position);
  }
};

// Axis-aligned bounding box. An empty box has min > max.
struct Aabb {
  Vec3 min = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 max = Vec3::Constant(-std::numeric_limits<double>::infinity());

  static Aabb infinite() {
    const double inf = std::numeric_limits<double>::infinity();
    return {Vec3::Constant(-inf), Vec3::Constant(inf)};
  }
  // The six comparisons all made and combined without a branch: in a broad phase each is a coin
  // toss, and a branch for each was mispredicted about once a test.
  bool overlaps(const Aabb& other) const {
    const bool x = (min.x() <= other.max.x()) & (other.min.x() <= max.x());
    const bool y = (min.y() <= other.max.y()) & (other.min.y() <= max.y());
    const bool z = (min.z() <= other.max.z()) & (other.min.z() <= max.z());
    return x & y & z;
  }
  bool is_bounded() const { return min.allFinite() && max.allFinite(); }
  Vec3 extent() const { return max - min; }
  void grow(const Vec3& p) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
  Aabb expanded(double margin) const {
    return {min - Vec3::Constant(margin), max + Vec3::Constant(margin)};
  }
};

// The world bounding box of a local box under a pose (exact for the box, conservative for its
// contents): the rotated half extents are |R| * h (Arvo, Graphics Gems 1990).
inline Aabb transform_aabb(const Aabb& local, const Pose& pose) {
  if (!local.is_bounded()) return Aabb::infinite();
  const Mat3 rotation = pose.orientation.toRotationMatrix();
  const Vec3 centre = pose.transform(0.5 * (local.min + local.max));
  const Vec3 half = rotation.cwiseAbs() * (0.5 * (local.max - local.min));
  return {centre - half, centre + half};
}

}  // namespace tumble
