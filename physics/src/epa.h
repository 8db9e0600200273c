// EPA: penetration depth, normal and witness points of two overlapping convex shapes.
//
// Source: van den Bergen, "Proximity queries and penetration depth computation on 3D game
// objects", GDC 2001, and "Collision Detection in Interactive 3D Environments", 2003, ch. 4.3.
//
// Steps: (1) grow the final GJK simplex into a polytope of the Minkowski difference A - B that
// contains the origin: a tetrahedron, or a bipyramid around a triangle; a triangle that already
// lies on a supporting plane is kept as a face of the answer rather than made into a sliver
// (the thin-simplex failure of naive EPA at tiny depths); (2) take the face nearest the origin and
// the support point w along its normal; (3) stop when w is no farther out than that face;
// otherwise remove the faces w can see (a flood fill across neighbours, so the hole is always
// one disc) and close the hole with a fan of faces to w; (4) the depth is the face's distance, the
// normal its outward normal, and the witness points come from the barycentric weights of the
// origin's projection on it. Every loop is bounded; bounds and degeneracies are reported.
#pragma once

#include <array>
#include <cmath>
#include <limits>

#include "gjk.h"

namespace tumble {

enum class EpaStatus { kConverged, kIterationLimit, kDegenerate };

struct EpaResult {
  EpaStatus status = EpaStatus::kConverged;
  double depth = 0;             // m, >= 0 up to rounding
  Vec3 normal = Vec3::UnitZ();  // unit, from A to B: moving B by depth * normal separates
  Vec3 point_a = Vec3::Zero(), point_b = Vec3::Zero();  // deepest points, common frame
  int iterations = 0;
};

struct EpaSettings {
  double tolerance = 1e-12;  // m: how far past the nearest face w may lie and still stop
  int max_iterations = 100;
};

namespace epa_detail {

constexpr int kMaxVertices = 128;
constexpr int kMaxFaces = 1024;

struct Face {
  std::array<int, 3> v;
  std::array<int, 3> adjacent;       // face across edge k = (v[k], v[k+1])
  std::array<int, 3> adjacent_edge;  // that edge's index in the adjacent face
  Vec3 normal;
  double distance;
  bool obsolete;
};

class Polytope {
 public:
  std::array<SimplexVertex, kMaxVertices> vertices;
  std::array<Face, kMaxFaces> faces;
  int vertex_count = 0, face_count = 0;

  int add_vertex(const SimplexVertex& v) {
    vertices[vertex_count] = v;
    return vertex_count++;
  }
  // False when the face is a sliver with no usable normal.
  bool set_plane(Face& f) const {
    const Vec3& a = vertices[f.v[0]].w;
    const Vec3 n = (vertices[f.v[1]].w - a).cross(vertices[f.v[2]].w - a);
    const double length = n.norm();
    if (!(length > 0) || !std::isfinite(length)) return false;
    f.normal = n / length;
    f.distance = f.normal.dot(a);
    return true;
  }
  // Builds the closed initial polytope from faces given by vertex triples (any orientation):
  // orients them away from `inside` and links neighbours.
  bool build(const int (*triples)[3], int count, const Vec3& inside);
  // Removes what `w` sees from face `seed` outwards and fans the hole to vertex `apex`.
  bool expand(int seed, int apex);
  int nearest_face() const {
    int best = -1;
    double best_distance = std::numeric_limits<double>::infinity();
    for (int i = 0; i < face_count; ++i)
      if (!faces[i].obsolete && faces[i].distance < best_distance) {
        best_distance = faces[i].distance;
        best = i;
      }
    return best;
  }
};

}  // namespace epa_detail

template <SupportShape A, SupportShape B>
EpaResult epa_penetration(const A& a, const B& b, const Simplex& start,
                          const EpaSettings& settings = {}) {
  using namespace epa_detail;
  auto support = [&](const Vec3& d) { return minkowski_support(a, b, d); };
  EpaResult result;
  const double tol = settings.tolerance;
  // The polytope is large (about 60 kB); one per thread, reused, keeps the stack small and the
  // step free of allocation.
  thread_local Polytope poly;
  poly.vertex_count = poly.face_count = 0;
  for (int i = 0; i < start.size; ++i) {
    bool repeated = false;
    for (int j = 0; j < poly.vertex_count; ++j)
      repeated |= poly.vertices[j].w == start.v[i].w;
    if (!repeated) poly.add_vertex(start.v[i]);
  }
  auto finish_flat = [&](const Vec3& normal, double depth, EpaStatus status) {
    result.status = status;
    result.normal = normal;
    result.depth = depth;
    // The deepest points: the origin projected on the supporting plane, read off the triangle.
    double w[3];
    const Vec3 p = normal * depth;
    gjk_detail::triangle_weights(poly.vertices[0].w, poly.vertices[1].w, poly.vertices[2].w, p, w);
    result.point_a =
        w[0] * poly.vertices[0].a + w[1] * poly.vertices[1].a + w[2] * poly.vertices[2].a;
    result.point_b =
        w[0] * poly.vertices[0].b + w[1] * poly.vertices[1].b + w[2] * poly.vertices[2].b;
    return result;
  };

  // (1) Raise the simplex to a triangle: add support points off the current point or line.
  static const Vec3 axes[6] = {Vec3::UnitX(),  -Vec3::UnitX(), Vec3::UnitY(),
                               -Vec3::UnitY(), Vec3::UnitZ(),  -Vec3::UnitZ()};
  if (poly.vertex_count == 4) {
    const Vec3& p0 = poly.vertices[0].w;
    const Vec3 e1 = poly.vertices[1].w - p0, e2 = poly.vertices[2].w - p0,
               e3 = poly.vertices[3].w - p0;
    if (std::abs(e1.dot(e2.cross(e3))) <= 1e-12 * e1.norm() * e2.norm() * e3.norm()) {
      // A flat tetrahedron: keep its largest face.
      const int faces4[4][3] = {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}};
      int best = 0;
      double best_area = -1;
      for (int f = 0; f < 4; ++f) {
        const Vec3& q = poly.vertices[faces4[f][0]].w;
        const double area = (poly.vertices[faces4[f][1]].w - q)
                                .cross(poly.vertices[faces4[f][2]].w - q)
                                .squaredNorm();
        if (area > best_area) {
          best_area = area;
          best = f;
        }
      }
      const SimplexVertex keep[3] = {poly.vertices[faces4[best][0]], poly.vertices[faces4[best][1]],
                                     poly.vertices[faces4[best][2]]};
      poly.vertex_count = 0;
      for (const auto& k : keep)
        poly.add_vertex(k);
    }
  }
  if (poly.vertex_count == 1) {
    for (const Vec3& d : axes) {
      const SimplexVertex s = support(d);
      if ((s.w - poly.vertices[0].w).norm() > tol) {
        poly.add_vertex(s);
        break;
      }
    }
  }
  if (poly.vertex_count == 2) {
    const Vec3 line = poly.vertices[1].w - poly.vertices[0].w;
    const Vec3 dir = line.normalized();
    int least = 0;
    dir.cwiseAbs().minCoeff(&least);
    const Vec3 first = dir.cross(Vec3::Unit(least)).normalized();
    const Vec3 second = dir.cross(first);
    for (int k = 0; k < 6 && poly.vertex_count == 2; ++k) {
      const double angle = k * (M_PI / 3);
      const SimplexVertex s = support(std::cos(angle) * first + std::sin(angle) * second);
      const Vec3 off = (s.w - poly.vertices[0].w);
      if ((off - off.dot(dir) * dir).norm() > tol) poly.add_vertex(s);
    }
  }
  if (poly.vertex_count < 3) {
    result.status = EpaStatus::kDegenerate;
    result.depth = 0;
    return result;
  }
  if (poly.vertex_count == 3) {
    // (1b) A triangle through (or next to) the origin: look for apexes on both sides.
    const Vec3& p0 = poly.vertices[0].w;
    Vec3 n = (poly.vertices[1].w - p0).cross(poly.vertices[2].w - p0);
    if (!(n.squaredNorm() > 0)) {
      result.status = EpaStatus::kDegenerate;
      return result;
    }
    n.normalize();
    const SimplexVertex up = support(n), down = support(-n);
    const double rise = n.dot(up.w - p0), fall = -n.dot(down.w - p0);
    const bool up_ok = rise > tol, down_ok = fall > tol;
    if (!up_ok && !down_ok) return finish_flat(n, n.dot(p0), EpaStatus::kDegenerate);
    const int ia = 0, ib = 1, ic = 2;
    if (up_ok && down_ok) {
      const int iu = poly.add_vertex(up), id = poly.add_vertex(down);
      const int triples[6][3] = {{ia, ib, iu}, {ib, ic, iu}, {ic, ia, iu},
                                 {ia, ib, id}, {ib, ic, id}, {ic, ia, id}};
      const Vec3 inside = (poly.vertices[0].w + poly.vertices[1].w + poly.vertices[2].w) / 3;
      if (!poly.build(triples, 6, inside)) return finish_flat(n, n.dot(p0), EpaStatus::kDegenerate);
    } else {
      // One side is flush with a supporting plane: the triangle is part of the boundary.
      const int iapex = poly.add_vertex(up_ok ? up : down);
      const int triples[4][3] = {{ia, ib, ic}, {ia, ib, iapex}, {ib, ic, iapex}, {ic, ia, iapex}};
      const Vec3 inside =
          (poly.vertices[0].w + poly.vertices[1].w + poly.vertices[2].w + poly.vertices[iapex].w) /
          4;
      if (!poly.build(triples, 4, inside)) return finish_flat(n, n.dot(p0), EpaStatus::kDegenerate);
    }
  } else {
    const int triples[4][3] = {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}};
    const Vec3 inside =
        (poly.vertices[0].w + poly.vertices[1].w + poly.vertices[2].w + poly.vertices[3].w) / 4;
    if (!poly.build(triples, 4, inside)) {
      result.status = EpaStatus::kDegenerate;
      return result;
    }
  }

  // (2)-(3) Expand towards the nearest face until the support point stops gaining.
  int nearest = poly.nearest_face();
  Face best = poly.faces[nearest];  // a copy: expand() may retire the face it came from
  result.status = EpaStatus::kIterationLimit;
  for (int iteration = 0; iteration < settings.max_iterations; ++iteration) {
    result.iterations = iteration + 1;
    const Face& face = poly.faces[nearest];
    best = face;
    const SimplexVertex w = support(face.normal);
    if (face.normal.dot(w.w) - face.distance <= tol) {
      result.status = EpaStatus::kConverged;
      break;
    }
    if (poly.vertex_count == kMaxVertices) break;
    const int apex = poly.add_vertex(w);
    if (!poly.expand(nearest, apex)) {
      result.status = EpaStatus::kDegenerate;
      break;
    }
    const int next = poly.nearest_face();
    if (next < 0) {
      result.status = EpaStatus::kDegenerate;
      break;
    }
    nearest = next;
  }
  // (4) Read the answer off the nearest face that was whole (after a failed expansion, the one
  // before it: its plane still bounds the difference, so the answer errs on the safe side).
  const Face& face = best;
  result.normal = face.normal;
  result.depth = face.distance;
  double weight[3];
  const SimplexVertex& va = poly.vertices[face.v[0]];
  const SimplexVertex& vb = poly.vertices[face.v[1]];
  const SimplexVertex& vc = poly.vertices[face.v[2]];
  gjk_detail::triangle_weights(va.w, vb.w, vc.w, face.normal * face.distance, weight);
  result.point_a = weight[0] * va.a + weight[1] * vb.a + weight[2] * vc.a;
  result.point_b = weight[0] * va.b + weight[1] * vb.b + weight[2] * vc.b;
  return result;
}

}  // namespace tumble
