// The pair routines of the narrow phase. Each works in one local frame given by the caller and
// writes its manifold (normal from A to B) in that frame; collide() moves it to the world.
#pragma once

#include <array>
#include <span>

#include "contact_record.h"
#include "physics/collision.h"

namespace tumble {

// The separating-axis feature a pair of polytopes' manifold came from (indices into the pair's
// polyhedra as collide() orders them), so that a later query of a pair that has barely moved can
// measure that feature alone instead of searching all of them.
struct PolytopeFeature {
  enum Kind : std::uint8_t { kNone, kFaceA, kFaceB, kEdges };
  Kind kind = kNone;
  std::uint32_t first = 0, second = 0;  // the face, or A's edge and B's edge
  bool searched = true;                 // false: the feature was given (`known`) and measured again
};

// collide() with the feature: with `known` (null: none) a pair of polytopes takes that feature
// without searching; `chosen` (null: not wanted) receives the feature its manifold came from
// (kNone for other shapes and for GJK/EPA).
std::uint32_t collide(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b,
                      const CollisionSettings& settings, const PolytopeFeature* known,
                      PolytopeFeature* chosen, ContactManifold* out);
// Whether `feature` names faces or edges that the pair (a, b) has.
bool feature_fits(const Shape& a, const Shape& b, const PolytopeFeature& feature);

// B placed in A's frame by (rotation, translation). Result in A's frame.
std::uint32_t collide_polytopes(const ConvexPolyhedron& a, const ConvexPolyhedron& b,
                                const Mat3& rotation, const Vec3& translation, double scale,
                                const CollisionSettings& settings, const PolytopeFeature* known,
                                PolytopeFeature* chosen, ContactManifold* out);
// Sphere A (centre at the origin of A's frame) against sphere or capsule B placed in A's frame.
std::uint32_t collide_sphere_sphere(double radius_a, double radius_b, const Vec3& centre_b,
                                    double margin, ContactManifold* out);
std::uint32_t collide_sphere_capsule(double radius_a, const Shape& capsule_b, const Mat3& rotation,
                                     const Vec3& translation, double margin, ContactManifold* out);
std::uint32_t collide_capsules(const Shape& a, const Shape& b, const Mat3& rotation,
                               const Vec3& translation, double margin, ContactManifold* out);
// A sphere or capsule A, given by its core segment p..q (p == q for a sphere) and radius in B's
// frame, against polytope B. Result in B's frame.
std::uint32_t collide_round_polytope(const Vec3& p, const Vec3& q, double radius,
                                     const Shape& polytope_b, const CollisionSettings& settings,
                                     ContactManifold* out);
// The same against any convex polyhedron of that size; `box_half_extents` (or null) says it is
// that box, for the closed form of a point.
std::uint32_t collide_round_polyhedron(const Vec3& p, const Vec3& q, double radius,
                                       const ConvexPolyhedron& poly, double size,
                                       const Vec3* box_half_extents,
                                       const CollisionSettings& settings, ContactManifold* out);
// Any shape A placed in the half-space's frame (solid z <= 0). Result in the half-space's frame.
std::uint32_t collide_half_space(const Shape& a, const Mat3& rotation, const Vec3& translation,
                                 double margin, ContactManifold* out);

// Terrain's (a heightfield's or a mesh's) contacts with one convex body: one manifold for each
// normal it pushes the body along (a box on a ridge touches two slopes), at most
// kMaxTerrainManifolds; a body on a flat stretch has one, the one it has on a plane. Cells
// visited per pair are bounded by kMaxTerrainCells, mesh triangles by kMaxTerrainTriangles
// (kTerrainCellLimit when cut).
constexpr int kMaxTerrainManifolds = 4;
constexpr std::size_t kMaxTerrainCells = 1 << 16;
constexpr std::size_t kMaxTerrainTriangles = 1 << 17;
struct TerrainContacts {
  std::array<ContactManifold, kMaxTerrainManifolds> manifolds;
  int count = 0;
};
// A, any convex shape, placed in the terrain's frame by (rotation, translation). Manifolds in
// the terrain's frame, normals from A into the terrain.
std::uint32_t collide_height_field(const Shape& a, const Mat3& rotation, const Vec3& translation,
                                   const HeightField& field, const CollisionSettings& settings,
                                   TerrainContacts* out);
std::uint32_t collide_mesh(const Shape& a, const Mat3& rotation, const Vec3& translation,
                           const TriangleMesh& mesh, const CollisionSettings& settings,
                           TerrainContacts* out);
// Whether a pair must go through collide_terrain (one of them is terrain).
inline bool is_terrain_pair(const Shape& a, const Shape& b) {
  return is_terrain(a.type()) || is_terrain(b.type());
}
// Whether a pair must go through collide_compound (one of them is a compound).
inline bool is_compound_pair(const Shape& a, const Shape& b) {
  return a.type() == ShapeType::kCompound || b.type() == ShapeType::kCompound;
}
// Pairs that may touch along several manifolds at once: terrain and compounds.
inline bool is_many_manifold_pair(const Shape& a, const Shape& b) {
  return is_terrain_pair(a, b) || is_compound_pair(a, b);
}
// The most manifolds a pair of these shapes can have: one per pair of parts (a convex shape is
// one part), up to kMaxTerrainManifolds each against terrain, at most kMaxPairManifolds.
std::size_t most_manifolds(const Shape& a, const Shape& b);
// A compound pair's part pairs keep their separating-axis features from step to step as a single
// pair of polytopes does (ContactPairRecord): the record of a part pair's manifold carries the
// two parts' indices in the top 16 bits of feature_first and feature_second (the faces and edges
// of a part number fewer than 2^16: a hull has at most 1024 points).
constexpr std::uint32_t kPartShift = 16;
constexpr std::uint32_t kPartFeatureMask = (1u << kPartShift) - 1;
// What the last step left of a compound pair, for kept features: its records, in order, and how
// far a part pair may have moved since its feature was searched (manifold_reuse times the
// smaller part's size; the bodies' outer radii bound the motion, relative_motion).
struct PartHistory {
  std::span<const ContactPairRecord> run;
  double reuse = 0;
  double outer_a = 0, outer_b = 0;
};
// Beside each manifold collide_compound keeps: the feature it came from (the parts in the top
// bits; kNone for round parts and terrain) and the record of `run` whose feature it kept
// (UINT32_MAX: searched afresh).
struct PartFeature {
  PolytopeFeature feature;
  std::uint32_t kept_from = UINT32_MAX;
};

// Every manifold of a compound pair, in the world, normals from a to b, in the order of A's
// parts and then B's; each point's feature id mixes in the two parts' indices. `room` holds at
// most room.size() manifolds (the deepest, kPairManifoldLimit when one is left out); *count says
// how many it holds. With `history`, a part pair of polytopes that has barely moved clips its
// kept feature without searching; `features` (empty, or as large as room) receives each kept
// manifold's feature.
std::uint32_t collide_compound(const Shape& a, const Pose& pose_a, const Shape& b,
                               const Pose& pose_b, const CollisionSettings& settings,
                               std::span<ContactManifold> room, std::size_t* count,
                               const PartHistory* history = nullptr,
                               std::span<PartFeature> features = {});
// collide_compound or collide_terrain, whichever the pair needs; room for most_manifolds(a, b).
// `history` and `features` as collide_compound's (terrain manifolds have no feature).
std::uint32_t collide_many(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b,
                           const CollisionSettings& settings, std::span<ContactManifold> room,
                           std::size_t* count, const PartHistory* history = nullptr,
                           std::span<PartFeature> features = {});
// Every manifold of a terrain pair, in the world, normals from a to b.
std::uint32_t collide_terrain(const Shape& a, const Pose& pose_a, const Shape& b,
                              const Pose& pose_b, const CollisionSettings& settings,
                              TerrainContacts* out);

}  // namespace tumble
