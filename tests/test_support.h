// Helpers shared by the tests: a portable seeded generator, random rotations, and an exact
// separating-axis reference for two boxes that shares no code with the engine.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <random>
#include <vector>

#include "physics/math.h"

namespace tumble::testing {

// mt19937_64 is specified exactly; the conversion to doubles is ours, so every platform draws the
// same numbers.
class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  int integer(int lo, int hi) { return lo + static_cast<int>(uniform() * (hi - lo + 1)); }
  Vec3 vector(double lo, double hi) {
    return Vec3(uniform(lo, hi), uniform(lo, hi), uniform(lo, hi));
  }
  Quat rotation() {
    // Shoemake's uniform random rotation.
    const double u1 = uniform(), u2 = uniform(), u3 = uniform();
    const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
    return Quat(b * std::cos(2 * M_PI * u3), a * std::sin(2 * M_PI * u2),
                a * std::cos(2 * M_PI * u2), b * std::sin(2 * M_PI * u3))
        .normalized();
  }
  Vec3 direction() {
    Vec3 v;
    do
      v = vector(-1, 1);
    while (v.squaredNorm() > 1 || v.squaredNorm() < 1e-6);
    return v.normalized();
  }

 private:
  std::mt19937_64 engine_;
};

struct ReferenceSat {
  double separation;  // > 0 separated, < 0 overlapping by -separation
  Vec3 axis;          // from A to B
  double runner_up;   // separation along the best axis that is not parallel to `axis`
};

// Brute force: project all 8 corners of both boxes on each of the 15 candidate axes.
inline ReferenceSat reference_box_sat(const Vec3& ha, const Pose& pa, const Vec3& hb,
                                      const Pose& pb) {
  const Mat3 ra = pa.orientation.toRotationMatrix(), rb = pb.orientation.toRotationMatrix();
  // Relative frame of A, so that far-off coordinates do not cost precision here either.
  const Mat3 r = ra.transpose() * rb;
  const Vec3 t = ra.transpose() * (pb.position - pa.position);
  std::array<Vec3, 8> ca, cb;
  for (int i = 0; i < 8; ++i) {
    const Vec3 s((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1);
    ca[i] = s.cwiseProduct(ha);
    cb[i] = r * s.cwiseProduct(hb) + t;
  }
  std::array<Vec3, 15> axes;
  int n = 0;
  for (int i = 0; i < 3; ++i)
    axes[n++] = Vec3::Unit(i);
  for (int i = 0; i < 3; ++i)
    axes[n++] = r.col(i);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const Vec3 c = Vec3::Unit(i).cross(r.col(j));
      if (c.norm() > 1e-9) axes[n++] = c.normalized();
    }
  ReferenceSat best{-std::numeric_limits<double>::infinity(), Vec3::UnitZ(),
                    -std::numeric_limits<double>::infinity()};
  std::vector<std::pair<double, Vec3>> all;
  for (int k = 0; k < n; ++k) {
    Vec3 axis = axes[k];
    double amin = 1e300, amax = -1e300, bmin = 1e300, bmax = -1e300;
    for (int i = 0; i < 8; ++i) {
      amin = std::min(amin, axis.dot(ca[i]));
      amax = std::max(amax, axis.dot(ca[i]));
      bmin = std::min(bmin, axis.dot(cb[i]));
      bmax = std::max(bmax, axis.dot(cb[i]));
    }
    const double forward = bmin - amax, backward = amin - bmax;
    const double sep = std::max(forward, backward);
    if (backward > forward) axis = -axis;
    all.push_back({sep, axis});
  }
  for (const auto& [sep, axis] : all)
    if (sep > best.separation) best = {sep, axis, best.runner_up};
  for (const auto& [sep, axis] : all)
    if (std::abs(axis.dot(best.axis)) < 1 - 1e-15) best.runner_up = std::max(best.runner_up, sep);
  best.axis = ra * best.axis;
  return best;
}

// Signed distance of a world point from a box surface (negative inside), exact.
inline double box_signed_distance(const Vec3& h, const Pose& pose, const Vec3& world) {
  const Vec3 p = pose.inverse_transform(world);
  const Vec3 q = p.cwiseAbs() - h;
  const double outside = q.cwiseMax(0.0).norm();
  return outside > 0 ? outside : q.maxCoeff();
}

// The eight corners of the box |x_i| <= half_i (to build the same box as a hull).
inline std::vector<Vec3> box_corners(const Vec3& half) {
  std::vector<Vec3> corners;
  for (int i = 0; i < 8; ++i)
    corners.emplace_back((i & 1) ? half.x() : -half.x(), (i & 2) ? half.y() : -half.y(),
                         (i & 4) ? half.z() : -half.z());
  return corners;
}

// The squared distance of segment p..q from the box |x_i| <= half_i, by a ternary search over
// the segment's parameter: that distance is convex along the segment. Shares no code with the
// engine's closed form (segment.h).
inline double segment_box_squared_distance_by_search(const Vec3& p, const Vec3& q,
                                                     const Vec3& half) {
  auto squared_at = [&](double t) {
    const Vec3 x = p + t * (q - p);
    return (x - x.cwiseMax(-half).cwiseMin(half)).squaredNorm();
  };
  double lo = 0, hi = 1;
  for (int k = 0; k < 200; ++k) {
    const double a = lo + (hi - lo) / 3, b = hi - (hi - lo) / 3;
    if (squared_at(a) <= squared_at(b))
      hi = b;
    else
      lo = a;
  }
  return std::min({squared_at(0), squared_at(1), squared_at(0.5 * (lo + hi))});
}

}  // namespace tumble::testing
