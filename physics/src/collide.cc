// Narrow-phase dispatch by shape pair. The lower ShapeType goes first, so each pair has one
// routine; a swapped pair's manifold is mirrored back. All work happens in one body's local frame
// (the relative pose is formed once, in world coordinates), so contacts between bodies far from
// the origin keep the precision of their size, not of their coordinates.
#include <vector>

#include "manifold.h"
#include "narrow_phase.h"
#include "physics/compound.h"

namespace tumble {
namespace {

std::uint32_t collide_ordered(const Shape& a, const Pose& pose_a, const Shape& b,
                              const Pose& pose_b, const CollisionSettings& settings,
                              const PolytopeFeature* known, PolytopeFeature* chosen,
                              ContactManifold* out) {
  const Mat3 ra = pose_a.orientation.toRotationMatrix();
  const Mat3 rb = pose_b.orientation.toRotationMatrix();
  const Vec3 offset = pose_b.position - pose_a.position;
  // B in A's frame, and A in B's frame.
  const Mat3 b_in_a = ra.transpose() * rb;
  const Vec3 b_at = ra.transpose() * offset;
  const Mat3 a_in_b = b_in_a.transpose();
  const Vec3 a_at = -(rb.transpose() * offset);
  const double margin = settings.margin;
  std::uint32_t flags = kCollisionOk;
  bool in_b_frame = false;

  switch (b.type()) {
    case ShapeType::kHeightField:  // collide_terrain's
    case ShapeType::kMesh:
    case ShapeType::kCompound:  // collide_compound's
      break;
    case ShapeType::kHalfSpace:
      flags = collide_half_space(a, a_in_b, a_at, margin, out);
      in_b_frame = true;
      break;
    case ShapeType::kSphere:
      flags = collide_sphere_sphere(a.radius(), b.radius(), b_at, margin, out);
      break;
    case ShapeType::kCapsule:
      flags = a.type() == ShapeType::kSphere
                  ? collide_sphere_capsule(a.radius(), b, b_in_a, b_at, margin, out)
                  : collide_capsules(a, b, b_in_a, b_at, margin, out);
      break;
    case ShapeType::kBox:
    case ShapeType::kHull:
      if (a.type() == ShapeType::kSphere || a.type() == ShapeType::kCapsule) {
        const Vec3 axis =
            a.type() == ShapeType::kCapsule ? Vec3(a_in_b.col(2) * a.half_height()) : Vec3::Zero();
        flags = collide_round_polytope(a_at - axis, a_at + axis, a.radius(), b, settings, out);
        in_b_frame = true;
      } else {
        flags = collide_polytopes(*a.polyhedron(), *b.polyhedron(), b_in_a, b_at,
                                  std::max(a.size(), b.size()), settings, known, chosen, out);
      }
      break;
  }
  if (in_b_frame)
    manifold_to_world(rb, pose_b.position, out);
  else
    manifold_to_world(ra, pose_a.position, out);
  return flags;
}

}  // namespace

std::uint32_t collide(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b,
                      const CollisionSettings& settings, const PolytopeFeature* known,
                      PolytopeFeature* chosen, ContactManifold* out) {
  out->count = 0;
  if (chosen != nullptr) *chosen = PolytopeFeature{};
  if (is_static_only(a.type()) && is_static_only(b.type())) return kCollisionOk;
  if (is_compound_pair(a, b)) {
    thread_local std::vector<ContactManifold> all(kMaxPairManifolds);
    std::size_t count = 0;
    const std::uint32_t flags = collide_compound(a, pose_a, b, pose_b, settings, all, &count);
    for (std::size_t c = 0; c < count; ++c)
      if (c == 0 || all[c].depth > out->depth) *out = all[c];
    return flags;
  }
  if (is_terrain_pair(a, b)) {
    TerrainContacts all;
    const std::uint32_t flags = collide_terrain(a, pose_a, b, pose_b, settings, &all);
    for (int c = 0; c < all.count; ++c)
      if (c == 0 || all.manifolds[c].depth > out->depth) *out = all.manifolds[c];
    return flags;
  }
  if (a.type() <= b.type())
    return collide_ordered(a, pose_a, b, pose_b, settings, known, chosen, out);
  const std::uint32_t flags = collide_ordered(b, pose_b, a, pose_a, settings, known, chosen, out);
  out->normal = -out->normal;
  for (int i = 0; i < out->count; ++i)
    std::swap(out->points[i].point_a, out->points[i].point_b);
  return flags;
}

std::uint32_t collide(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b,
                      const CollisionSettings& settings, ContactManifold* out) {
  return collide(a, pose_a, b, pose_b, settings, nullptr, nullptr, out);
}

bool feature_fits(const Shape& a, const Shape& b, const PolytopeFeature& feature) {
  if (feature.kind == PolytopeFeature::kNone) return true;
  if (is_compound_pair(a, b)) {
    // The parts' indices in the top bits (kPartShift); a shape that is not a compound is part 0.
    const auto part = [](const Shape& shape, std::uint32_t index) -> const Shape* {
      if (shape.type() != ShapeType::kCompound) return index == 0 ? &shape : nullptr;
      const auto parts = shape.compound()->parts();
      return index < parts.size() ? &parts[index].shape : nullptr;
    };
    const Shape* part_a = part(a, feature.first >> kPartShift);
    const Shape* part_b = part(b, feature.second >> kPartShift);
    if (part_a == nullptr || part_b == nullptr) return false;
    return feature_fits(*part_a, *part_b,
                        {feature.kind, feature.first & kPartFeatureMask,
                         feature.second & kPartFeatureMask, feature.searched});
  }
  const ConvexPolyhedron* first = a.type() <= b.type() ? a.polyhedron() : b.polyhedron();
  const ConvexPolyhedron* second = a.type() <= b.type() ? b.polyhedron() : a.polyhedron();
  if (first == nullptr || second == nullptr) return false;
  switch (feature.kind) {
    case PolytopeFeature::kFaceA:
      return feature.first < first->faces.size();
    case PolytopeFeature::kFaceB:
      return feature.first < second->faces.size();
    case PolytopeFeature::kEdges:
      return feature.first < first->edges.size() && feature.second < second->edges.size();
    case PolytopeFeature::kNone:
      break;
  }
  return true;
}

}  // namespace tumble
