// Small rotations of orientations.
#pragma once

#include <cmath>

#include "physics/math.h"

namespace tumble {

// The rotation by the rotation vector `theta` (axis times angle, rad) as a quaternion: exact, so
// orientations stay unit length up to rounding however fast a body spins.
inline Quat rotation_quaternion(const Vec3& theta) {
  const double t2 = theta.squaredNorm();
  if (t2 < 0.0625) {
    // Below 0.25 rad, cos(t/2) and sin(t/2)/t as their Taylor series in t^2 to the t^10 terms
    // (the next below 1e-19 of the sums), with no square root, sine or cosine: every body's turn
    // asks this every substep, and libm's sincos was 2.2% of an awake pile's instructions and
    // 2.9% of a chain's.
    const double c =
        1 + t2 * (-1.0 / 8 +
                  t2 * (1.0 / 384 +
                        t2 * (-1.0 / 46080 + t2 * (1.0 / 10321920 + t2 * (-1.0 / 3715891200)))));
    const double s =
        0.5 + t2 * (-1.0 / 48 +
                    t2 * (1.0 / 3840 + t2 * (-1.0 / 645120 +
                                             t2 * (1.0 / 185794560 + t2 * (-1.0 / 81749606400)))));
    return Quat(c, s * theta.x(), s * theta.y(), s * theta.z());
  }
  const double angle = std::sqrt(t2);
  const double half = 0.5 * angle;
  const Vec3 axis = theta * (std::sin(half) / angle);
  return Quat(std::cos(half), axis.x(), axis.y(), axis.z());
}

// Where the rotation by `theta` takes r, less r and less the first-order theta x r: the turn's
// curvature, (sin t / t - 1) theta x r + ((1 - cos t) / t^2) theta x (theta x r) with t = |theta|
// (Rodrigues' formula). Below t = 0.25 rad both factors are their Taylor series to the t^10
// terms (the next ones below 1e-15 of the sums), with no square root, sine or cosine: the
// joints' velocity rows ask this of both bodies at every visit.
inline Vec3 turn_curvature(const Vec3& theta, const Vec3& r) {
  const double t2 = theta.squaredNorm();
  const Vec3 across = theta.cross(r);
  double first, second;
  if (t2 < 0.0625) {
    // -1/3!, 1/5!, ... and 1/2!, -1/4!, ...: Horner's rule in t^2.
    constexpr double s1 = -1.0 / 6, s2 = 1.0 / 120, s3 = -1.0 / 5040, s4 = 1.0 / 362880,
                     s5 = -1.0 / 39916800;
    constexpr double c0 = 1.0 / 2, c1 = -1.0 / 24, c2 = 1.0 / 720, c3 = -1.0 / 40320,
                     c4 = 1.0 / 3628800, c5 = -1.0 / 479001600;
    first = t2 * (s1 + t2 * (s2 + t2 * (s3 + t2 * (s4 + t2 * s5))));
    second = c0 + t2 * (c1 + t2 * (c2 + t2 * (c3 + t2 * (c4 + t2 * c5))));
  } else {
    const double t = std::sqrt(t2);
    first = std::sin(t) / t - 1;
    second = (1 - std::cos(t)) / t2;
  }
  return first * across + second * theta.cross(across);
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
