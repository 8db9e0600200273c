// Small rotations of orientations.
#pragma once

#include <cmath>

#include "physics/math.h"

namespace tumble {

// The rotation by the rotation vector `theta` (axis times angle, rad) as a quaternion: exact, so
// orientations stay unit length up to rounding however fast a body spins.
inline Quat rotation_quaternion(const Vec3& theta) {
  const double angle = theta.norm();
  if (angle < 1e-8) {
    // sin(x/2)/x = 1/2 - x^2/48 + ...: the series is exact to rounding at this size.
    const Quat q(1 - angle * angle / 8, 0.5 * theta.x(), 0.5 * theta.y(), 0.5 * theta.z());
    return q.normalized();
  }
  const double half = 0.5 * angle;
  const Vec3 axis = theta * (std::sin(half) / angle);
  return Quat(std::cos(half), axis.x(), axis.y(), axis.z());
}

// `q` turned by `theta` given in world axes, renormalised against drift.
inline Quat rotated(const Quat& q, const Vec3& theta) {
  return (rotation_quaternion(theta) * q).normalized();
}

// The angle (rad, 0 to pi) of the rotation that takes orientation `from` to `to`: atan2 of the
// half-angle's sine and cosine, accurate for tiny turns where acos of the cosine is not.
inline double angle_between(const Quat& from, const Quat& to) {
  const Quat turn = from.conjugate() * to;
  return 2 * std::atan2(turn.vec().norm(), std::abs(turn.w()));
}

// Where a pose moved at constant velocities (v: m/s of the origin, w: rad/s, world axes) is
// after dt: exact, as a kinematic body moves.
inline Pose moved_by(const Pose& pose, const Vec3& v, const Vec3& w, double dt) {
  return {pose.position + dt * v, rotated(pose.orientation, dt * w)};
}

}  // namespace tumble
