// Contact manifolds between two shapes, and the queries that produce them.
#pragma once

#include <array>
#include <cstdint>

#include "physics/math.h"
#include "physics/shape.h"

namespace tumble {

struct ContactPoint {
  Vec3 point_a;  // m, world: on (or inside) the surface of A
  Vec3 point_b;  // m, world: on (or inside) the surface of B
  // m: penetration along the normal, > 0 when overlapping, < 0 for a speculative contact
  // separated by that gap.
  double depth = 0;
  // Names the pair of features (faces, edges, vertices) that made the point; the same while the
  // same features touch, so a solver can carry impulses over from step to step.
  std::uint64_t feature_id = 0;
};

struct ContactManifold {
  Vec3 normal = Vec3::UnitZ();  // unit, world, from A towards B: moving B along it separates them
  // m: the pair's penetration along the normal (exact for polytopes): moving B by depth * normal
  // leaves the shapes just touching. Points carry their own, never larger, depths.
  double depth = 0;
  std::array<ContactPoint, 4> points;
  int count = 0;
};

enum class NarrowPhaseMethod : std::uint8_t {
  kAuto,    // the fastest exact method for each pair: SAT for small polytopes (boxes), GJK/EPA
            // when the edge pairs to test grow large (hulls); see docs/PERFORMANCE.md
  kSat,     // the separating-axis test for every pair of polytopes
  kGjkEpa,  // GJK and EPA for every pair of polytopes
};

struct CollisionSettings {
  // m: pairs separated by less than this still produce (speculative) contacts.
  double margin = 0;
  NarrowPhaseMethod method = NarrowPhaseMethod::kAuto;
  // Contact features for a solver: a face contact (several points) is kept unless an edge pair,
  // or the other body's face, separates the shapes by more than `feature_slack` (m) plus
  // `feature_slack_relative` of the penetration. A stack then keeps its four-point manifolds
  // when a box tilts a little; `depth` stays the exact pair penetration either way. 0 (the
  // default) picks the exact minimum-penetration feature.
  double feature_slack = 0;
  double feature_slack_relative = 0;
  // GJK/EPA path: a face whose normal is within this angle (rad) of the contact normal is
  // clipped as a face. The default only accepts faces parallel to EPA's accuracy.
  double face_angle = 4.5e-7;
};

// The most manifolds one pair of bodies keeps: every touching pair of a compound's parts (and
// each normal a part touches terrain along) has its own, the deepest kMaxPairManifolds of them
// (kPairManifoldLimit when cut).
inline constexpr std::size_t kMaxPairManifolds = 64;
// The most pairs of parts whose bounds meet that one pair of bodies collides in a step (each a
// convex pair: a compound's parts are at most 256, hulls of at most 1024 points); past it the
// rest are left out and kPairManifoldLimit is raised.
inline constexpr std::size_t kMaxPartPairs = 4096;

// Outcome flags a query raises; a query that hits an iteration bound still returns its best answer.
enum CollisionFlags : std::uint32_t {
  kCollisionOk = 0,
  kGjkIterationLimit = 1u << 0,
  kEpaIterationLimit = 1u << 1,
  kEpaDegenerate = 1u << 2,
  kTerrainCellLimit = 1u << 3,  // a body over more terrain cells than a pair may visit
  // A pair of bodies touching along more manifolds than it keeps, or with more pairs of parts
  // near each other than it meets (kMaxPairManifolds, kMaxPartPairs).
  kPairManifoldLimit = 1u << 4,
};

// Contacts between shape `a` at `pose_a` and shape `b` at `pose_b`. Returns the flags; `out->count`
// is 0 when the shapes are farther apart than the margin. Two static-only shapes (half-spaces,
// heightfields) never collide. Against terrain, where a body can touch along several normals, and
// for a compound, whose parts touch on their own, this is the deepest of the manifolds (World's
// contacts keep them all).
std::uint32_t collide(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b,
                      const CollisionSettings& settings, ContactManifold* out);

}  // namespace tumble
