// Building contact manifolds: clipping an incident face against a reference face, single points,
// and reducing many points to the four that keep the contact area.
#pragma once

#include <span>
#include <vector>

#include "physics/collision.h"

namespace tumble {

struct ClipVertex {
  Vec3 point;
  std::uint32_t tag;  // which incident vertex, or which incident edge crossed which side plane
};

// Room for a manifold's candidate points before reduce_points: up to kCandidatesOnStack on the
// caller's stack, left unset (ContactPoint's member initialisers would zero every slot on every
// call; each slot used is made whole where it is written), more in this thread's buffer, which
// only grows.
constexpr std::size_t kCandidatesOnStack = 32;
union CandidateSlots {
  CandidateSlots() {}
  ContactPoint slots[kCandidatesOnStack];
};
ContactPoint* thread_candidate_room(std::size_t count);
inline ContactPoint* candidate_room(CandidateSlots& stack, std::size_t count) {
  return count <= kCandidatesOnStack ? stack.slots : thread_candidate_room(count);
}

// Feature ids: kind in the top bits so that points made by different routes never share an id.
enum FeatureKind : std::uint64_t {
  kFeatureFaceA = 1ull << 60,
  kFeatureFaceB = 2ull << 60,
  kFeatureEdges = 3ull << 60,
  kFeatureVertex = 4ull << 60,
  kFeatureRound = 5ull << 60,
};
inline std::uint64_t feature_id(FeatureKind kind, std::uint64_t first, std::uint64_t second,
                                std::uint64_t third) {
  return kind | ((first & 0xFFFFF) << 40) | ((second & 0xFFFFF) << 20) | (third & 0xFFFFF);
}

// A polytope placed in a common frame: x = rotation * local + translation.
struct PlacedPolyhedron {
  const ConvexPolyhedron* polyhedron;
  Mat3 rotation;
  Vec3 translation;
  Vec3 point(std::uint32_t i) const { return rotation * polyhedron->vertices[i] + translation; }
  Vec3 face_normal(std::uint32_t f) const { return rotation * polyhedron->faces[f].normal; }
  double face_offset(std::uint32_t f) const {
    return polyhedron->faces[f].offset + face_normal(f).dot(translation);
  }
};

// The face of `incident` whose normal is most opposed to `normal` (common frame).
std::uint32_t most_opposed_face(const PlacedPolyhedron& incident, const Vec3& normal);

// Face contact: clips the incident face against the side planes of `reference_face` and keeps the
// points within `margin` of the reference plane. `reference_is_a` sets which side the points and
// the normal (A to B) belong to. Result in the common frame.
void clip_face_contact(const PlacedPolyhedron& reference, std::uint32_t reference_face,
                       const PlacedPolyhedron& incident, std::uint32_t incident_face,
                       bool reference_is_a, double margin, ContactManifold* out);

// Reduces candidates to at most four: the deepest, the farthest from it, and the two that span the
// largest area on either side of that line. Output in `out` (count and points).
void reduce_points(std::span<const ContactPoint> candidates, const Vec3& normal,
                   ContactManifold* out);

// Moves a manifold from a local frame (x_world = rotation * x + translation) to the world.
void manifold_to_world(const Mat3& rotation, const Vec3& translation, ContactManifold* m);

}  // namespace tumble
