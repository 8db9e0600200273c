// Closest points between segments (Ericson, "Real-Time Collision Detection", 2005, 5.1.9).
#pragma once

#include <algorithm>

#include "physics/math.h"

namespace tumble {

struct SegmentClosest {
  double s, t;  // parameters in [0, 1] on the first and second segment
  Vec3 on_first, on_second;
};

inline SegmentClosest closest_between_segments(const Vec3& p1, const Vec3& q1, const Vec3& p2,
                                               const Vec3& q2) {
  const Vec3 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0, t = 0;
  if (a <= 0 && e <= 0) {
  } else if (a <= 0) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= 0) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2);
      const double denom = a * e - b * b;
      // Parallel segments (denom ~ 0): any s works; 0 keeps the answer deterministic.
      s = denom > 1e-14 * a * e ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  return {s, t, p1 + s * d1, p2 + t * d2};
}

// The point of segment p..q nearest to x, as a parameter in [0, 1].
inline double closest_on_segment(const Vec3& p, const Vec3& q, const Vec3& x) {
  const Vec3 d = q - p;
  const double length2 = d.squaredNorm();
  return length2 > 0 ? std::clamp((x - p).dot(d) / length2, 0.0, 1.0) : 0.0;
}

// A unit vector orthogonal to `v` (which need not be unit).
inline Vec3 any_orthogonal(const Vec3& v) {
  int least = 0;
  v.cwiseAbs().minCoeff(&least);
  return v.cross(Vec3::Unit(least)).normalized();
}

}  // namespace tumble
