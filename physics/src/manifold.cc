// Sutherland-Hodgman clipping of the incident face against the reference face's side planes, as
// in Box2D's and Bullet's polygon clipping (Gregorius, "Robust contact creation for physics
// simulations", GDC 2015). Tags on clip vertices become feature ids, so a point keeps its id as
// long as the same incident vertex, or the same incident edge crossing the same side, makes it.
#include "manifold.h"

#include <limits>

namespace tumble {
namespace {

constexpr std::uint32_t kEdgeTag = 0x80000;

}  // namespace

std::uint32_t most_opposed_face(const PlacedPolyhedron& incident, const Vec3& normal) {
  const Vec3 local = incident.rotation.transpose() * normal;
  std::uint32_t best = 0;
  double best_dot = std::numeric_limits<double>::infinity();
  const auto& faces = incident.polyhedron->faces;
  for (std::uint32_t f = 0; f < faces.size(); ++f) {
    const double d = faces[f].normal.dot(local);
    if (d < best_dot) {
      best_dot = d;
      best = f;
    }
  }
  return best;
}

void clip_face_contact(const PlacedPolyhedron& reference, std::uint32_t reference_face,
                       const PlacedPolyhedron& incident, std::uint32_t incident_face,
                       bool reference_is_a, double margin, ContactManifold* out) {
  thread_local std::vector<ClipVertex> polygon, clipped;
  thread_local std::vector<ContactPoint> candidates;
  polygon.clear();
  const auto& inc_face = incident.polyhedron->faces[incident_face];
  for (std::uint32_t k = 0; k < inc_face.count; ++k)
    polygon.push_back({incident.point(incident.polyhedron->face_vertices[inc_face.first + k]), k});

  const auto& ref_face = reference.polyhedron->faces[reference_face];
  const Vec3 n = reference.face_normal(reference_face);
  const double offset = reference.face_offset(reference_face);
  for (std::uint32_t k = 0; k < ref_face.count && !polygon.empty(); ++k) {
    const Vec3 p = reference.point(reference.polyhedron->face_vertices[ref_face.first + k]);
    const Vec3 q = reference.point(
        reference.polyhedron->face_vertices[ref_face.first + (k + 1) % ref_face.count]);
    const Vec3 side = (q - p).cross(n);  // outward for a counter-clockwise loop
    const double side_offset = side.dot(p);
    clipped.clear();
    for (std::size_t i = 0; i < polygon.size(); ++i) {
      const ClipVertex& a = polygon[i];
      const ClipVertex& b = polygon[(i + 1) % polygon.size()];
      const double da = side.dot(a.point) - side_offset;
      const double db = side.dot(b.point) - side_offset;
      if (da <= 0) clipped.push_back(a);
      if ((da < 0 && db > 0) || (da > 0 && db < 0)) {
        const double t = da / (da - db);
        // The crossing is named by the incident edge (its first vertex's tag) and the side.
        clipped.push_back(
            {a.point + t * (b.point - a.point), kEdgeTag | ((a.tag & 0xFF) << 8) | k});
      }
    }
    std::swap(polygon, clipped);
  }

  candidates.clear();
  for (const ClipVertex& v : polygon) {
    const double separation = n.dot(v.point) - offset;
    if (separation > margin) continue;
    ContactPoint c;
    const Vec3 on_reference = v.point - separation * n;
    c.point_a = reference_is_a ? on_reference : v.point;
    c.point_b = reference_is_a ? v.point : on_reference;
    c.depth = -separation;
    c.feature_id = feature_id(reference_is_a ? kFeatureFaceA : kFeatureFaceB, reference_face,
                              incident_face, v.tag);
    candidates.push_back(c);
  }
  // The incident body's deepest vertex fixes the pair's depth. In deep overlaps the incident face
  // can lie wholly outside the reference face's prism; that vertex is then the one contact.
  const std::uint32_t deepest =
      incident.polyhedron->support_index(incident.rotation.transpose() * -n);
  const Vec3 v = incident.point(deepest);
  const double deepest_separation = n.dot(v) - offset;
  out->depth = -deepest_separation;
  if (candidates.empty() && deepest_separation <= margin) {
    const Vec3 on_reference = v - deepest_separation * n;
    candidates.push_back(
        {reference_is_a ? on_reference : v, reference_is_a ? v : on_reference, -deepest_separation,
         feature_id(kFeatureVertex, reference_face, deepest, reference_is_a ? 1 : 2)});
  }
  out->normal = reference_is_a ? n : Vec3(-n);
  reduce_points(candidates, out->normal, out);
}

void reduce_points(std::span<const ContactPoint> candidates, const Vec3& normal,
                   ContactManifold* out) {
  const std::size_t count = candidates.size();
  if (count <= 4) {
    for (std::size_t i = 0; i < count; ++i)
      out->points[i] = candidates[i];
    out->count = static_cast<int>(count);
    return;
  }
  auto position = [&](std::size_t i) -> const Vec3& { return candidates[i].point_b; };
  std::size_t first = 0;
  for (std::size_t i = 1; i < count; ++i)
    if (candidates[i].depth > candidates[first].depth) first = i;
  std::size_t second = first;
  double far2 = -1;
  for (std::size_t i = 0; i < count; ++i) {
    const double d2 = (position(i) - position(first)).squaredNorm();
    if (d2 > far2) {
      far2 = d2;
      second = i;
    }
  }
  const Vec3 line = position(second) - position(first);
  std::size_t third = first, fourth = first;
  double most = 0, least = 0;
  for (std::size_t i = 0; i < count; ++i) {
    const double area = normal.dot(line.cross(position(i) - position(first)));
    if (area > most) {
      most = area;
      third = i;
    }
    if (area < least) {
      least = area;
      fourth = i;
    }
  }
  int n = 0;
  for (std::size_t i : {first, second, third, fourth}) {
    bool repeated = false;
    for (int k = 0; k < n; ++k)
      repeated |= out->points[k].feature_id == candidates[i].feature_id &&
                  out->points[k].point_b == candidates[i].point_b;
    if (!repeated) out->points[n++] = candidates[i];
  }
  out->count = n;
}

void manifold_to_world(const Mat3& rotation, const Vec3& translation, ContactManifold* m) {
  m->normal = rotation * m->normal;
  for (int i = 0; i < m->count; ++i) {
    m->points[i].point_a = rotation * m->points[i].point_a + translation;
    m->points[i].point_b = rotation * m->points[i].point_b + translation;
  }
}

}  // namespace tumble
