// Compound shapes against everything: each part of a compound meets each part (or the whole) of
// the other body on its own, with the narrow phase's convex routines, and every touching pair of
// parts keeps its own manifold, as Bullet's btCompoundCollisionAlgorithm and Jolt's
// CompoundShape do. Parts are culled by their bounds first, so a pair pays for the parts that
// can touch.
#include <algorithm>
#include <cmath>

#include "narrow_phase.h"
#include "physics/compound.h"

namespace tumble {
namespace {

struct PlacedPart {
  const Shape* shape;
  Pose pose;     // world
  double reach;  // m: the part's outer radius about its origin
  std::uint32_t index;
};

// The parts of `shape` (a compound's, or the shape itself as its only part) that can reach
// `other` placed in the world: each part's bounds, in the shape's frame, against the other's
// bounds brought into that frame, so that a part left out costs one box test and no placing.
void place_parts(const Shape& shape, const Pose& pose, const Shape& other, const Pose& other_pose,
                 double margin, std::vector<PlacedPart>* out) {
  out->clear();
  if (shape.type() != ShapeType::kCompound) {
    out->push_back({&shape, pose, shape.outer_radius(), 0});
    return;
  }
  const Quat into = pose.orientation.conjugate();
  const Pose other_here{into * (other_pose.position - pose.position),
                        into * other_pose.orientation};
  const Aabb reach = transform_aabb(other.local_bounds(), other_here).expanded(margin);
  const auto parts = shape.compound()->parts();
  out->reserve(parts.size());  // room for every part at once, however many touch this time
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const Compound::Part& part = parts[i];
    if (!part.bounds.overlaps(reach)) continue;
    const Pose placed{pose.transform(part.pose.position), pose.orientation * part.pose.orientation};
    out->push_back({&part.shape, placed, part.shape.outer_radius(), static_cast<std::uint32_t>(i)});
  }
}

// A part pair's points are told apart from another pair's by mixing in both indices.
std::uint64_t part_feature(std::uint32_t part_a, std::uint32_t part_b, std::uint64_t id) {
  const std::uint64_t pair = (static_cast<std::uint64_t>(part_a) << 32 | part_b) + 1;
  return id ^ (pair * 0xD6E8FEB86659FD93ull);
}

// Keeps the deepest manifolds the room holds, in the order they were found.
std::uint32_t keep(const ContactManifold& manifold, std::uint32_t part_a, std::uint32_t part_b,
                   std::span<ContactManifold> room, std::size_t* count) {
  ContactManifold marked = manifold;
  for (int i = 0; i < marked.count; ++i)
    marked.points[i].feature_id = part_feature(part_a, part_b, marked.points[i].feature_id);
  if (*count < room.size()) {
    room[(*count)++] = marked;
    return kCollisionOk;
  }
  const auto kept = room.first(*count);
  auto shallowest = std::min_element(
      kept.begin(), kept.end(),
      [](const ContactManifold& x, const ContactManifold& y) { return x.depth < y.depth; });
  if (marked.depth > shallowest->depth) {
    std::move(shallowest + 1, kept.end(), shallowest);
    kept.back() = marked;
  }
  return kPairManifoldLimit;
}

}  // namespace

std::uint32_t collide_compound(const Shape& a, const Pose& pose_a, const Shape& b,
                               const Pose& pose_b, const CollisionSettings& settings,
                               std::span<ContactManifold> room, std::size_t* count) {
  *count = 0;
  if (room.empty()) return kCollisionOk;
  thread_local std::vector<PlacedPart> parts_a, parts_b;
  place_parts(a, pose_a, b, pose_b, settings.margin, &parts_a);
  if (parts_a.empty()) return kCollisionOk;
  place_parts(b, pose_b, a, pose_a, settings.margin, &parts_b);
  std::uint32_t flags = kCollisionOk;
  TerrainContacts terrain;
  ContactManifold manifold;
  for (const PlacedPart& part_a : parts_a) {
    for (const PlacedPart& part_b : parts_b) {
      // Parts farther apart than their outer spheres (and the margin) cannot touch.
      const double reach = part_a.reach + part_b.reach + settings.margin;
      if (std::isfinite(reach) &&
          (part_b.pose.position - part_a.pose.position).squaredNorm() > reach * reach)
        continue;
      if (is_terrain_pair(*part_a.shape, *part_b.shape)) {
        flags |= collide_terrain(*part_a.shape, part_a.pose, *part_b.shape, part_b.pose, settings,
                                 &terrain);
        for (int c = 0; c < terrain.count; ++c)
          flags |= keep(terrain.manifolds[c], part_a.index, part_b.index, room, count);
        continue;
      }
      flags |= collide(*part_a.shape, part_a.pose, *part_b.shape, part_b.pose, settings, nullptr,
                       nullptr, &manifold);
      if (manifold.count > 0) flags |= keep(manifold, part_a.index, part_b.index, room, count);
    }
  }
  return flags;
}

std::size_t most_manifolds(const Shape& a, const Shape& b) {
  const auto parts = [](const Shape& shape) -> std::size_t {
    return shape.type() == ShapeType::kCompound ? shape.compound()->parts().size() : 1;
  };
  const std::size_t per_pair = is_terrain_pair(a, b) ? kMaxTerrainManifolds : 1;
  return std::min(kMaxPairManifolds, parts(a) * parts(b) * per_pair);
}

std::uint32_t collide_many(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b,
                           const CollisionSettings& settings, std::span<ContactManifold> room,
                           std::size_t* count) {
  if (is_compound_pair(a, b)) return collide_compound(a, pose_a, b, pose_b, settings, room, count);
  TerrainContacts terrain;
  const std::uint32_t flags = collide_terrain(a, pose_a, b, pose_b, settings, &terrain);
  *count = std::min(room.size(), static_cast<std::size_t>(terrain.count));
  std::copy_n(terrain.manifolds.begin(), *count, room.begin());
  return flags;
}

}  // namespace tumble
