// Anything against the ground half-space (solid z <= 0 of its frame): every vertex or core end
// below the plane (or within the margin above it) is a contact; more than four are reduced.
#include <limits>

#include "manifold.h"
#include "narrow_phase.h"

namespace tumble {

std::uint32_t collide_half_space(const Shape& a, const Mat3& rotation, const Vec3& translation,
                                 double margin, ContactManifold* out) {
  out->count = 0;
  out->normal = -Vec3::UnitZ();  // from A into the ground
  thread_local std::vector<ContactPoint> candidates;
  candidates.clear();
  auto consider = [&](const Vec3& core, double radius, std::uint64_t id) {
    const double depth = radius - core.z();
    if (depth < -margin) return;
    const Vec3 on_a = core - Vec3(0, 0, radius);
    candidates.push_back({on_a, Vec3(core.x(), core.y(), 0), depth, id});
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
        candidates.push_back({v, Vec3(v.x(), v.y(), 0), -z, kFeatureVertex | i});
      }
      break;
    }
    case ShapeType::kHalfSpace:
      return kCollisionOk;
  }
  out->depth = -std::numeric_limits<double>::infinity();
  for (const ContactPoint& c : candidates)
    out->depth = std::max(out->depth, c.depth);
  reduce_points(candidates, out->normal, out);
  return kCollisionOk;
}

}  // namespace tumble
