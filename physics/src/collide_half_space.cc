// Anything against the ground half-space (solid z <= 0 of its frame): every vertex or core end
// below the plane (or within the margin above it) is a contact; more than four are reduced.
#include <limits>
#include <new>
#include <span>

#include "manifold.h"
#include "narrow_phase.h"

namespace tumble {

std::uint32_t collide_half_space(const Shape& a, const Mat3& rotation, const Vec3& translation,
                                 double margin, ContactManifold* out) {
  out->count = 0;
  out->normal = -Vec3::UnitZ();  // from A into the ground
  // At most one candidate per vertex (a sphere has one, a capsule two).
  CandidateSlots stack_candidates;
  ContactPoint* candidates = candidate_room(
      stack_candidates, a.polyhedron() != nullptr ? a.polyhedron()->vertices.size() : 2);
  std::size_t count = 0;
  auto consider = [&](const Vec3& core, double radius, std::uint64_t id) {
    const double depth = radius - core.z();
    if (depth < -margin) return;
    const Vec3 on_a = core - Vec3(0, 0, radius);
    new (&candidates[count++]) ContactPoint{on_a, Vec3(core.x(), core.y(), 0), depth, id};
  };
  switch (a.type()) {
    case ShapeType::kSphere:
      consider(translation, a.radius(), kFeatureVertex);
      break;
    case ShapeType::kCapsule: {
      const Vec3 axis = rotation.col(2) * a.half_height();
      consider(translation - axis, a.radius(), kFeatureVertex | 0);
      consider(translation + axis, a.radius(), kFeatureVertex | 1);
      break;
    }
    case ShapeType::kBox:
    case ShapeType::kHull: {
      const auto& vertices = a.polyhedron()->vertices;
      // Only the height of each vertex decides, so only the z row of the rotation is needed.
      const Vec3 up = rotation.row(2).transpose();
      for (std::uint32_t i = 0; i < vertices.size(); ++i) {
        const double z = up.dot(vertices[i]) + translation.z();
        if (-z < -margin) continue;
        const Vec3 v = rotation * vertices[i] + translation;
        new (&candidates[count++]) ContactPoint{v, Vec3(v.x(), v.y(), 0), -z, kFeatureVertex | i};
      }
      break;
    }
    case ShapeType::kHalfSpace:
    case ShapeType::kHeightField:
    case ShapeType::kMesh:
    case ShapeType::kCompound:  // collide_compound meets the ground part by part
      return kCollisionOk;
  }
  out->depth = -std::numeric_limits<double>::infinity();
  const std::span<const ContactPoint> found(candidates, count);
  for (const ContactPoint& c : found)
    out->depth = std::max(out->depth, c.depth);
  reduce_points(found, out->normal, out);
  return kCollisionOk;
}

}  // namespace tumble
