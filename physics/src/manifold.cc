// Sutherland-Hodgman clipping of the incident face against the reference face's side planes, as
// in Box2D's and Bullet's polygon clipping (Gregorius, "Robust contact creation for physics
// simulations", GDC 2015). Tags on clip vertices become feature ids, so a point keeps its id as
// long as the same incident vertex, or the same incident edge crossing the same side, makes it.
#include "manifold.h"

#include <algorithm>
#include <limits>
#include <new>

namespace tumble {
namespace {

constexpr std::uint32_t kEdgeTag = 0x80000;

constexpr std::size_t kPolygonOnStack = 32;

// Where clip_face_contact's polygon and its clipped copy live: first on its stack, then, for a
// polygon that could outgrow `capacity`, in this thread's buffers, which only grow.
struct ClipSpace {
  ClipVertex* polygon;
  ClipVertex* clipped;
  std::size_t capacity;

  // Room for `needed` vertices, keeping the polygon's first `size`.
  void make_room(std::size_t size, std::size_t needed) {
    if (needed > capacity) move_to_heap(size, needed);
  }

  [[gnu::noinline]] void move_to_heap(std::size_t size, std::size_t needed) {
    thread_local std::vector<ClipVertex> heap_polygon, heap_clipped;
    // The polygon may already live in the buffers that are about to grow: keep it aside first.
    const std::vector<ClipVertex> kept(polygon, polygon + size);
    heap_polygon.resize(std::max(needed, heap_polygon.size()));
    heap_clipped.resize(heap_polygon.size());
    std::copy(kept.begin(), kept.end(), heap_polygon.begin());
    polygon = heap_polygon.data();
    clipped = heap_clipped.data();
    capacity = heap_polygon.size();
  }
};

// Clips the polygon `in` (n vertices) against the half-space side . x <= side_offset into `out`,
// which has room for 2 n (each edge gives at most its first vertex and a crossing: a convex
// polygon gains at most one vertex, but rounding can leave one slightly concave); returns the
// count. `side_index` names the crossings.
std::size_t clip_against_side(const ClipVertex* in, std::size_t n, const Vec3& side,
                              double side_offset, std::uint32_t side_index, ClipVertex* out) {
  std::size_t count = 0;
  // Each vertex's distance is measured once: as the end of one edge, then as the start of the next.
  const double d_first = side.dot(in[0].point) - side_offset;
  double db = d_first;
  for (std::size_t i = 0; i < n; ++i) {
    const ClipVertex& a = in[i];
    const bool last = i + 1 == n;
    const ClipVertex& b = in[last ? 0 : i + 1];
    const double da = db;
    db = last ? d_first : side.dot(b.point) - side_offset;
    if (da <= 0) out[count++] = a;
    if ((da < 0 && db > 0) || (da > 0 && db < 0)) {
      const double t = da / (da - db);
      // The crossing is named by the incident edge (its first vertex's tag) and the side.
      out[count++] = {a.point + t * (b.point - a.point),
                      kEdgeTag | ((a.tag & 0xFF) << 8) | side_index};
    }
  }
  return count;
}

}  // namespace

ContactPoint* thread_candidate_room(std::size_t count) {
  thread_local std::vector<ContactPoint> room;
  if (room.size() < count) room.resize(count);
  return room.data();
}

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
  const auto& inc_face = incident.polyhedron->faces[incident_face];
  const auto& ref_face = reference.polyhedron->faces[reference_face];
  // Box faces and most hull faces clip on the stack; a polygon that could outgrow it moves to
  // this thread's buffers (ClipSpace::move_to_heap).
  ClipVertex stack_polygon[kPolygonOnStack], stack_clipped[kPolygonOnStack];
  ClipSpace space{stack_polygon, stack_clipped, kPolygonOnStack};
  std::size_t size = inc_face.count;
  space.make_room(0, size);
  for (std::uint32_t k = 0; k < inc_face.count; ++k)
    space.polygon[k] = {incident.point(incident.polyhedron->face_vertices[inc_face.first + k]), k};

  const Vec3 n = reference.face_normal(reference_face);
  const double offset = reference.face_offset(reference_face);
  const std::uint32_t* ref_vertices = &reference.polyhedron->face_vertices[ref_face.first];
  const Vec3 first_corner = reference.point(ref_vertices[0]);
  Vec3 p = first_corner;
  for (std::uint32_t k = 0; k < ref_face.count && size > 0; ++k) {
    const Vec3 q = k + 1 < ref_face.count ? reference.point(ref_vertices[k + 1]) : first_corner;
    const Vec3 side = (q - p).cross(n);  // outward for a counter-clockwise loop
    space.make_room(size, 2 * size);
    size = clip_against_side(space.polygon, size, side, side.dot(p), k, space.clipped);
    std::swap(space.polygon, space.clipped);
    p = q;
  }

  // At most one candidate per clipped vertex, or the deepest vertex alone.
  CandidateSlots stack_candidates;
  ContactPoint* candidates = candidate_room(stack_candidates, size + 1);
  std::size_t candidate_count = 0;
  for (const ClipVertex& v : std::span(space.polygon, size)) {
    const double separation = n.dot(v.point) - offset;
    if (separation > margin) continue;
    const Vec3 on_reference = v.point - separation * n;
    new (&candidates[candidate_count++])
        ContactPoint{reference_is_a ? on_reference : v.point,
                     reference_is_a ? v.point : on_reference, -separation,
                     feature_id(reference_is_a ? kFeatureFaceA : kFeatureFaceB, reference_face,
                                incident_face, v.tag)};
  }
  // The incident body's deepest vertex fixes the pair's depth. In deep overlaps the incident face
  // can lie wholly outside the reference face's prism; that vertex is then the one contact.
  const std::uint32_t deepest =
      incident.polyhedron->support_index(incident.rotation.transpose() * -n);
  const Vec3 v = incident.point(deepest);
  const double deepest_separation = n.dot(v) - offset;
  out->depth = -deepest_separation;
  if (candidate_count == 0 && deepest_separation <= margin) {
    const Vec3 on_reference = v - deepest_separation * n;
    new (&candidates[candidate_count++]) ContactPoint{
        reference_is_a ? on_reference : v, reference_is_a ? v : on_reference, -deepest_separation,
        feature_id(kFeatureVertex, reference_face, deepest, reference_is_a ? 1 : 2)};
  }
  out->normal = reference_is_a ? n : Vec3(-n);
  reduce_points(std::span(candidates, candidate_count), out->normal, out);
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
