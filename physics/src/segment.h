// Closest points between segments (Ericson, "Real-Time Collision Detection", 2005, 5.1.9).
#pragma once

#include <algorithm>
#include <cmath>

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

// The point of segment p..q nearest to the box |x_i| <= half_i (in the box's frame), as a
// parameter in [0, 1], and its squared distance from the box. That distance, the sum over the
// axes of (|x_i| - half_i)^2 where positive, is convex along the segment and one quadratic
// between the parameters where the segment crosses a face's plane (at most six of them): the
// least of the pieces' minima is the exact answer, a few dozen operations where GJK iterates
// over the box's corners. Where the segment meets the box the distance is 0 (rounding aside).
struct SegmentBoxClosest {
  double t = 0, squared_distance = 0;
};
inline SegmentBoxClosest closest_segment_box(const Vec3& p, const Vec3& q, const Vec3& half) {
  const Vec3 u = q - p;
  double breaks[8];
  int count = 0;
  breaks[count++] = 0;
  for (int i = 0; i < 3; ++i) {
    if (u[i] == 0) continue;
    for (const double plane : {-half[i], half[i]}) {
      const double t = (plane - p[i]) / u[i];
      if (t > 0 && t < 1) {
        int k = count++;  // sorted as they come: at most six
        for (; k > 1 && breaks[k - 1] > t; --k)
          breaks[k] = breaks[k - 1];
        breaks[k] = t;
      }
    }
  }
  breaks[count++] = 1;
  auto squared_distance_at = [&](double t) {
    const Vec3 x = p + t * u;
    return (x - x.cwiseMax(-half).cwiseMin(half)).squaredNorm();
  };
  SegmentBoxClosest best{0, squared_distance_at(0)};
  for (int k = 0; k + 1 < count; ++k) {
    const double lo = breaks[k], hi = breaks[k + 1];
    // Which planes the piece lies beyond, from its middle (its ends may sit on a plane).
    const Vec3 middle = p + (0.5 * (lo + hi)) * u;
    double uu = 0, uc = 0;
    for (int i = 0; i < 3; ++i) {
      double plane;
      if (middle[i] > half[i])
        plane = half[i];
      else if (middle[i] < -half[i])
        plane = -half[i];
      else
        continue;
      uu += u[i] * u[i];
      uc += u[i] * (p[i] - plane);
    }
    const double t = uu > 0 ? std::clamp(-uc / uu, lo, hi) : lo;
    const double squared = squared_distance_at(t);
    if (squared < best.squared_distance) best = {t, squared};
  }
  return best;
}

// How a segment p..q that meets the box |x_i| <= half_i (in the box's frame) leaves it the shortest
// way: the unit normal from the segment into the box, how far the segment must move against it
// (negative: the segment is that far clear along it), and the segment's deepest point along it.
// The segment and the box are apart exactly along some face normal of their Minkowski difference,
// and those are the box's three axes and the segment's direction crossed with each of them (the
// faces a box edge sweeps along the segment): the least overlap over these six axes is the depth,
// exact where EPA approaches it by iteration. (They are the axes of the separating-axis test of a
// segment and a box, Ericson, "Real-Time Collision Detection", 2005, 5.3.3.) A crossing wins only
// by more than `bias` (m), so that a segment across a face keeps the face's normal, not an edge's
// that ties with it to rounding.
struct SegmentBoxPenetration {
  Vec3 normal;
  double depth;
  Vec3 deepest;
};
inline SegmentBoxPenetration segment_box_penetration(const Vec3& p, const Vec3& q, const Vec3& half,
                                                     double bias) {
  const Vec3 centre = 0.5 * (p + q), reach = 0.5 * (q - p);
  const auto face_overlap = [&](int k) {
    return half[k] + std::abs(reach[k]) - std::abs(centre[k]);
  };
  // (From axis 0 rather than from infinity: a non-finite segment still names an axis.)
  SegmentBoxPenetration best{Vec3::Zero(), face_overlap(0), p};
  int best_axis = 0;  // 0-2: the box's axis; 3-5: the crossing with axis k - 3
  Vec3 best_unit = Vec3::Zero();
  for (int k = 1; k < 3; ++k) {
    const double overlap = face_overlap(k);
    if (overlap < best.depth) {
      best.depth = overlap;
      best_axis = k;
    }
  }
  const double face_depth = best.depth;
  for (int k = 0; k < 3; ++k) {
    const Vec3 crossing = reach.cross(Vec3::Unit(k));
    const double length = crossing.norm();
    // Along an axis of the box the segment sweeps no face of its own.
    if (!(length > 1e-12 * reach.norm())) continue;
    const Vec3 unit = crossing / length;
    const double overlap = half.dot(unit.cwiseAbs()) - std::abs(centre.dot(unit));
    if (overlap < best.depth && overlap < face_depth - bias) {
      best.depth = overlap;
      best_axis = 3 + k;
      best_unit = unit;
    }
  }
  // Into the box: against the side the segment's centre lies on.
  if (best_axis < 3) {
    best.normal = Vec3::Zero();
    best.normal[best_axis] = centre[best_axis] > 0 ? -1.0 : 1.0;
    best.deepest = p.dot(best.normal) >= q.dot(best.normal) ? p : q;
    return best;
  }
  best.normal = centre.dot(best_unit) > 0 ? Vec3(-best_unit) : best_unit;
  // The box's edge along axis k nearest the segment (its corner against the normal), and the
  // segment's point nearest that edge.
  const int k = best_axis - 3;
  Vec3 edge_end = Vec3::Zero();
  for (int i = 0; i < 3; ++i)
    edge_end[i] = best.normal[i] > 0 ? -half[i] : half[i];
  Vec3 edge_start = edge_end;
  edge_start[k] = -half[k];
  edge_end[k] = half[k];
  best.deepest = closest_between_segments(p, q, edge_start, edge_end).on_first;
  return best;
}

// A unit vector orthogonal to `v` (which need not be unit).
inline Vec3 any_orthogonal(const Vec3& v) {
  int least = 0;
  v.cwiseAbs().minCoeff(&least);
  return v.cross(Vec3::Unit(least)).normalized();
}

}  // namespace tumble
