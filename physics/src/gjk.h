// GJK distance between two convex shapes given by support functions.
//
// Source: Gilbert, Johnson, Keerthi, "A fast procedure for computing the distance between complex
// objects in three-dimensional space", IEEE J. Robotics and Automation 1988; termination and
// robustness after van den Bergen, "Collision Detection in Interactive 3D Environments", 2003.
//
// Steps: (1) keep a simplex of up to four points of the Minkowski difference A - B together with
// the support points of A and B that made them; (2) find the point v of the simplex closest to
// the origin and drop the vertices it does not need (Voronoi-region tests, Ericson "Real-Time
// Collision Detection" 5.1); (3) ask for the support point w in direction -v; stop when w adds
// nothing (|v|^2 - v.w small, w already in the simplex, or |v| stops shrinking), when the
// origin is inside a tetrahedron, or when |v| is within the tolerance of zero; (4) the closest
// points on A and B come from the barycentric weights of v.
//
// Degenerate simplices are expected, not assumed away: a segment or triangle with (nearly) no
// length or area falls back to its best sub-simplex, and a flat tetrahedron is treated by its
// faces. Every loop is bounded; hitting the bound is reported.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

#include "support.h"

namespace tumble {

struct SimplexVertex {
  Vec3 w = Vec3::Zero();  // a - b
  Vec3 a = Vec3::Zero();  // support point of A
  Vec3 b = Vec3::Zero();  // support point of B
};

struct Simplex {
  std::array<SimplexVertex, 4> v;
  std::array<double, 4> weight{};  // barycentric weights of the closest point
  int size = 0;
};

enum class GjkStatus { kSeparated, kIntersecting, kIterationLimit };

struct GjkResult {
  GjkStatus status = GjkStatus::kSeparated;
  double distance = 0;                                  // m
  Vec3 point_a = Vec3::Zero(), point_b = Vec3::Zero();  // closest points, common frame
  Simplex simplex;
  int iterations = 0;
};

struct GjkSettings {
  double tolerance = 1e-12;     // m: |v| below this counts as touching; scale with the shapes
  double relative_gap = 1e-13;  // stop when |v|^2 - v.w <= relative_gap * |v|^2
  int max_iterations = 128;
};

// The point of A - B farthest along d, with the support points of A and B that make it.
template <SupportShape A, SupportShape B>
SimplexVertex minkowski_support(const A& a, const B& b, const Vec3& d) {
  SimplexVertex sv;
  sv.a = a.support(d);
  sv.b = b.support(-d);
  sv.w = sv.a - sv.b;
  return sv;
}

namespace gjk_detail {

// Closest point of a simplex to the origin; reduces the simplex to the support set of that point
// and writes its weights. Returns the point.
Vec3 closest_point(Simplex& s);
// Barycentric weights of `p` (in the triangle's plane) with respect to triangle a, b, c.
Vec3 triangle_weights(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p, double* weights);

}  // namespace gjk_detail

template <SupportShape A, SupportShape B>
GjkResult gjk_distance(const A& a, const B& b, const Vec3& initial_direction,
                       const GjkSettings& settings = {}) {
  GjkResult result;
  Simplex& s = result.simplex;
  auto support = [&](const Vec3& d) { return minkowski_support(a, b, d); };
  Vec3 d = initial_direction.squaredNorm() > 0 ? initial_direction : Vec3(1, 0, 0);
  s.v[0] = support(-d);
  s.weight[0] = 1;
  s.size = 1;
  Vec3 v = s.v[0].w;
  double v2 = v.squaredNorm();
  const double tolerance2 = settings.tolerance * settings.tolerance;

  result.status = GjkStatus::kIterationLimit;
  for (int iteration = 0; iteration < settings.max_iterations; ++iteration) {
    result.iterations = iteration + 1;
    if (v2 <= tolerance2) {
      result.status = GjkStatus::kIntersecting;
      break;
    }
    const SimplexVertex w = support(-v);
    // w is no farther along -v than the simplex already reaches: v is the closest point.
    if (v2 - v.dot(w.w) <= std::max(settings.relative_gap * v2, tolerance2)) {
      result.status = GjkStatus::kSeparated;
      break;
    }
    bool repeated = false;
    for (int i = 0; i < s.size; ++i)
      repeated |= (s.v[i].w == w.w);
    if (repeated) {
      result.status = GjkStatus::kSeparated;
      break;
    }
    const Simplex previous = s;
    s.v[s.size++] = w;
    const Vec3 next = gjk_detail::closest_point(s);
    const double next2 = next.squaredNorm();
    if (s.size == 4) {  // the origin is inside the tetrahedron
      v = Vec3::Zero();
      v2 = 0;
      result.status = GjkStatus::kIntersecting;
      break;
    }
    if (next2 >= v2) {  // rounding: no progress, keep the better simplex
      s = previous;
      result.status = GjkStatus::kSeparated;
      break;
    }
    v = next;
    v2 = next2;
  }
  if (result.status == GjkStatus::kIntersecting && v2 <= tolerance2) {
    result.distance = 0;
  } else {
    result.distance = std::sqrt(v2);
  }
  result.point_a = Vec3::Zero();
  result.point_b = Vec3::Zero();
  for (int i = 0; i < s.size; ++i) {
    result.point_a += s.weight[i] * s.v[i].a;
    result.point_b += s.weight[i] * s.v[i].b;
  }
  return result;
}

}  // namespace tumble
