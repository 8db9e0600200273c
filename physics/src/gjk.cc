// Closest point of a simplex to the origin. Barycentric weights come from areas and volumes
// projected on the best-conditioned axes (the signed-volume idea of Montanari, Petrinic, Barbieri,
// "Improving the GJK algorithm for faster and more reliable distance queries between convex
// objects", ACM TOG 2017), so a thin triangle loses accuracy like 1/sin(angle), not 1/sin^2.
#include "gjk.h"

namespace tumble::gjk_detail {
namespace {

double cross2(const Vec3& x, const Vec3& y, int i, int j) {
  return x[i] * y[j] - x[j] * y[i];
}

// Copies only the live vertices: the rest of a simplex is never read.
void assign(Simplex& to, const Simplex& from) {
  for (int i = 0; i < from.size; ++i) {
    to.v[i] = from.v[i];
    to.weight[i] = from.weight[i];
  }
  to.size = from.size;
}

// Closest point on segment s.v[i0]..s.v[i1]; writes a reduced simplex into `out`.
Vec3 closest_on_segment(const Simplex& s, int i0, int i1, Simplex& out) {
  const Vec3& a = s.v[i0].w;
  const Vec3& b = s.v[i1].w;
  const Vec3 ab = b - a;
  const double length2 = ab.squaredNorm();
  const double t = length2 > 0 ? -a.dot(ab) / length2 : 0.0;
  if (t <= 0 || !(length2 > 0)) {
    // A zero-length segment keeps the vertex nearer the origin.
    const int keep = (length2 > 0 || a.squaredNorm() <= b.squaredNorm()) ? i0 : i1;
    out.v[0] = s.v[keep];
    out.weight[0] = 1;
    out.size = 1;
    return out.v[0].w;
  }
  if (t >= 1) {
    out.v[0] = s.v[i1];
    out.weight[0] = 1;
    out.size = 1;
    return b;
  }
  out.v[0] = s.v[i0];
  out.v[1] = s.v[i1];
  out.weight[0] = 1 - t;
  out.weight[1] = t;
  out.size = 2;
  return a + t * ab;
}

Vec3 closest_on_triangle(const Simplex& s, int i0, int i1, int i2, Simplex& out) {
  const Vec3& a = s.v[i0].w;
  const Vec3& b = s.v[i1].w;
  const Vec3& c = s.v[i2].w;
  const Vec3 n = (b - a).cross(c - a);
  const double n2 = n.squaredNorm();
  const double scale = (b - a).squaredNorm() * (c - a).squaredNorm();
  if (n2 > 1e-28 * scale && n2 > 0) {
    const Vec3 p = n * (n.dot(a) / n2);  // the origin projected on the plane
    int k = 0;
    n.cwiseAbs().maxCoeff(&k);
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    const double area = n[k];
    const double u = cross2(b - p, c - p, i, j) / area;
    const double v = cross2(c - p, a - p, i, j) / area;
    const double w = 1 - u - v;
    if (u >= 0 && v >= 0 && w >= 0) {
      out.v[0] = s.v[i0];
      out.v[1] = s.v[i1];
      out.v[2] = s.v[i2];
      out.weight[0] = u;
      out.weight[1] = v;
      out.weight[2] = w;
      out.size = 3;
      return p;
    }
  }
  // Outside the face region, or a sliver: the nearest edge decides.
  const int edges[3][2] = {{i0, i1}, {i1, i2}, {i2, i0}};
  Vec3 best = Vec3::Zero();
  double best2 = std::numeric_limits<double>::infinity();
  for (const auto& e : edges) {
    Simplex candidate;
    const Vec3 q = closest_on_segment(s, e[0], e[1], candidate);
    if (q.squaredNorm() < best2) {
      best2 = q.squaredNorm();
      best = q;
      assign(out, candidate);
    }
  }
  return best;
}

}  // namespace

Vec3 triangle_weights(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p, double* weights) {
  const Vec3 n = (b - a).cross(c - a);
  int k = 0;
  n.cwiseAbs().maxCoeff(&k);
  const int i = (k + 1) % 3, j = (k + 2) % 3;
  const double area = n[k];
  if (area == 0) {
    weights[0] = 1;
    weights[1] = weights[2] = 0;
    return a;
  }
  weights[0] = cross2(b - p, c - p, i, j) / area;
  weights[1] = cross2(c - p, a - p, i, j) / area;
  weights[2] = 1 - weights[0] - weights[1];
  return weights[0] * a + weights[1] * b + weights[2] * c;
}

Vec3 closest_point(Simplex& s) {
  Simplex out;
  Vec3 result;
  switch (s.size) {
    case 1:
      s.weight[0] = 1;
      return s.v[0].w;
    case 2:
      result = closest_on_segment(s, 0, 1, out);
      break;
    case 3:
      result = closest_on_triangle(s, 0, 1, 2, out);
      break;
    default: {
      const Vec3& a = s.v[0].w;
      const Vec3 ab = s.v[1].w - a, ac = s.v[2].w - a, ad = s.v[3].w - a;
      const double volume = ab.dot(ac.cross(ad));
      const double scale = ab.norm() * ac.norm() * ad.norm();
      if (std::abs(volume) > 1e-14 * scale) {
        // Weights of the origin: each is the volume with that vertex replaced by the origin.
        const Vec3 o = -a;
        const double wb = o.dot(ac.cross(ad)) / volume;
        const double wc = ab.dot(o.cross(ad)) / volume;
        const double wd = ab.dot(ac.cross(o)) / volume;
        const double wa = 1 - wb - wc - wd;
        if (wa >= 0 && wb >= 0 && wc >= 0 && wd >= 0) {
          s.weight = {wa, wb, wc, wd};
          return Vec3::Zero();
        }
      }
      const int faces[4][3] = {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}};
      double best2 = std::numeric_limits<double>::infinity();
      for (const auto& f : faces) {
        Simplex candidate;
        const Vec3 q = closest_on_triangle(s, f[0], f[1], f[2], candidate);
        if (q.squaredNorm() < best2) {
          best2 = q.squaredNorm();
          result = q;
          assign(out, candidate);
        }
      }
      break;
    }
  }
  assign(s, out);
  return result;
}

}  // namespace tumble::gjk_detail
