// Compound shapes against everything: each part of a compound meets each part (or the whole) of
// the other body on its own, with the narrow phase's convex routines, and every touching pair of
// parts keeps its own manifold, as Bullet's btCompoundCollisionAlgorithm and Jolt's
// CompoundShape do. Parts are culled by their bounds first, so a pair pays for the parts that
// can touch.
#include <algorithm>
#include <cmath>

#include "contact_pairs.h"
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

// Keeps the deepest manifolds the room holds, in the order they were found, with their features
// beside them (when `features` is not empty).
std::uint32_t keep(const ContactManifold& manifold, const PartFeature& feature,
                   std::uint32_t part_a, std::uint32_t part_b, std::span<ContactManifold> room,
                   std::span<PartFeature> features, std::size_t* count) {
  ContactManifold marked = manifold;
  for (int i = 0; i < marked.count; ++i)
    marked.points[i].feature_id = part_feature(part_a, part_b, marked.points[i].feature_id);
  std::size_t at = *count;
  std::uint32_t flags = kCollisionOk;
  if (*count < room.size()) {
    ++*count;
  } else {
    flags = kPairManifoldLimit;
    const auto kept = room.first(*count);
    const auto shallowest = std::min_element(
        kept.begin(), kept.end(),
        [](const ContactManifold& x, const ContactManifold& y) { return x.depth < y.depth; });
    if (!(marked.depth > shallowest->depth)) return flags;
    const auto gone = static_cast<std::size_t>(shallowest - kept.begin());
    std::move(kept.begin() + gone + 1, kept.end(), kept.begin() + gone);
    if (!features.empty())
      std::move(features.begin() + gone + 1, features.begin() + *count, features.begin() + gone);
    at = *count - 1;
  }
  room[at] = marked;
  if (!features.empty()) features[at] = feature;
  return flags;
}

// The feature a part pair kept from the last step, if it has one and has barely moved since it
// was searched: its index in the history's run, or UINT32_MAX.
std::uint32_t kept_feature(const PartHistory& history, std::uint32_t part_a, std::uint32_t part_b,
                           const Shape& shape_a, const Shape& shape_b, const Pose& pose_a,
                           const Pose& pose_b) {
  for (std::size_t k = 0; k < history.run.size(); ++k) {
    const ContactPairRecord& record = history.run[k];
    if (record.feature_kind == PolytopeFeature::kNone ||
        record.feature_first >> kPartShift != part_a ||
        record.feature_second >> kPartShift != part_b)
      continue;
    const double motion = relative_motion(record, pose_a, pose_b, history.outer_a, history.outer_b);
    if (motion > history.reuse * std::min(shape_a.size(), shape_b.size())) return UINT32_MAX;
    return static_cast<std::uint32_t>(k);
  }
  return UINT32_MAX;
}

}  // namespace

std::uint32_t collide_compound(const Shape& a, const Pose& pose_a, const Shape& b,
                               const Pose& pose_b, const CollisionSettings& settings,
                               std::span<ContactManifold> room, std::size_t* count,
                               const PartHistory* history, std::span<PartFeature> features) {
  *count = 0;
  if (room.empty()) return kCollisionOk;
  thread_local std::vector<PlacedPart> parts_a, parts_b;
  place_parts(a, pose_a, b, pose_b, settings.margin, &parts_a);
  if (parts_a.empty()) return kCollisionOk;
  place_parts(b, pose_b, a, pose_a, settings.margin, &parts_b);
  std::uint32_t flags = kCollisionOk;
  TerrainContacts terrain;
  ContactManifold manifold;
  std::size_t met = 0;
  for (const PlacedPart& part_a : parts_a) {
    for (const PlacedPart& part_b : parts_b) {
      // Parts farther apart than their outer spheres (and the margin) cannot touch.
      const double reach = part_a.reach + part_b.reach + settings.margin;
      if (std::isfinite(reach) &&
          (part_b.pose.position - part_a.pose.position).squaredNorm() > reach * reach)
        continue;
      // Two compounds heaped into one another could ask for every pair of 256 parts each (of
      // hulls of 1024 points): a body pair meets at most kMaxPartPairs pairs of parts a step.
      if (++met > kMaxPartPairs) return flags | kPairManifoldLimit;
      if (is_terrain_pair(*part_a.shape, *part_b.shape)) {
        flags |= collide_terrain(*part_a.shape, part_a.pose, *part_b.shape, part_b.pose, settings,
                                 &terrain);
        for (int c = 0; c < terrain.count; ++c)
          flags |= keep(terrain.manifolds[c], PartFeature{}, part_a.index, part_b.index, room,
                        features, count);
        continue;
      }
      PolytopeFeature known, chosen;
      std::uint32_t kept_from = UINT32_MAX;
      if (history != nullptr && part_a.shape->polyhedron() != nullptr &&
          part_b.shape->polyhedron() != nullptr) {
        kept_from = kept_feature(*history, part_a.index, part_b.index, *part_a.shape, *part_b.shape,
                                 pose_a, pose_b);
        if (kept_from != UINT32_MAX) {
          const ContactPairRecord& record = history->run[kept_from];
          known = {static_cast<PolytopeFeature::Kind>(record.feature_kind),
                   record.feature_first & kPartFeatureMask,
                   record.feature_second & kPartFeatureMask, false};
        }
      }
      flags |= collide(*part_a.shape, part_a.pose, *part_b.shape, part_b.pose, settings,
                       kept_from != UINT32_MAX ? &known : nullptr, &chosen, &manifold);
      if (manifold.count == 0) continue;
      PartFeature feature;
      if (chosen.kind != PolytopeFeature::kNone) {
        feature.feature = chosen;
        feature.feature.first |= part_a.index << kPartShift;
        feature.feature.second |= part_b.index << kPartShift;
        if (!chosen.searched) feature.kept_from = kept_from;
      }
      flags |= keep(manifold, feature, part_a.index, part_b.index, room, features, count);
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
                           std::size_t* count, const PartHistory* history,
                           std::span<PartFeature> features) {
  if (is_compound_pair(a, b))
    return collide_compound(a, pose_a, b, pose_b, settings, room, count, history, features);
  for (PartFeature& feature : features)
    feature = PartFeature{};
  TerrainContacts terrain;
  const std::uint32_t flags = collide_terrain(a, pose_a, b, pose_b, settings, &terrain);
  *count = std::min(room.size(), static_cast<std::size_t>(terrain.count));
  std::copy_n(terrain.manifolds.begin(), *count, room.begin());
  return flags;
}

}  // namespace tumble
