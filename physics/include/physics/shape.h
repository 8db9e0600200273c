// Convex shapes. Each is made from a definition struct, validated on creation, and is immutable
// afterwards so that many bodies can share one.
#pragma once

#include <memory>
#include <variant>
#include <vector>

#include "physics/height_field.h"
#include "physics/math.h"
#include "physics/polyhedron.h"
#include "physics/status.h"
#include "physics/triangle_mesh.h"

namespace tumble {

// A ball. radius: m, > 0.
struct SphereDef {
  double radius = 0.5;
};
// A segment from (0,0,-half_height) to (0,0,+half_height) swept by a ball.
// radius: m, > 0; half_height: m, > 0 (half the length of the cylindrical part).
struct CapsuleDef {
  double radius = 0.25;
  double half_height = 0.5;
};
// The box [-h, h]^3. half_extents: m, each > 0. The engine's own arithmetic is in half extents;
// every other interface (scene JSON, the API, the CLI, Python) gives a box by its full `size`,
// which of_size() takes.
struct BoxDef {
  Vec3 half_extents = Vec3::Constant(0.5);
  static BoxDef of_size(const Vec3& size) { return {0.5 * size}; }
};
// The convex hull of `points` (m, in the body frame). At least 4 points spanning a volume, at
// most kMaxHullPoints (every contact query walks the hull's vertices, so their number bounds the
// time a step can take); duplicates, interior and coplanar points are fine.
inline constexpr std::size_t kMaxHullPoints = 1024;
struct HullDef {
  std::vector<Vec3> points;
};
// The solid region z <= 0 of its frame (an infinite ground); its surface normal is the frame's +z.
// Only static bodies may use it.
struct HalfSpaceDef {};
// HeightFieldDef (physics/height_field.h): terrain; only static bodies may use it.
// TriangleMeshDef (physics/triangle_mesh.h): static geometry of triangles; only static bodies.

// One body made of several convex parts (spheres, capsules, boxes, hulls), each placed by a pose
// in the body's frame: a table of five boxes, a dumbbell. The mass properties are the parts'
// together at the body's one density (where parts overlap, the overlap counts once per part, as
// in Bullet and Jolt); each part touches other bodies with contacts of its own. 1 to
// kMaxCompoundParts parts (every pair of bodies walks the parts, so their number bounds the time
// a step can take).
inline constexpr std::size_t kMaxCompoundParts = 256;
struct CompoundPart;
struct CompoundDef {
  std::vector<CompoundPart> parts;
};

using ShapeDef = std::variant<SphereDef, CapsuleDef, BoxDef, HullDef, HalfSpaceDef, HeightFieldDef,
                              TriangleMeshDef, CompoundDef>;

struct CompoundPart {
  ShapeDef shape;  // convex: a sphere, capsule, box or hull
  Pose pose;       // the part's frame in the body's (orientation normalized on creation)
};

// Ordered so that collision dispatch can always put the lower type first (the values are the
// state format's: a new type goes last).
enum class ShapeType : std::uint8_t {
  kSphere,
  kCapsule,
  kBox,
  kHull,
  kHalfSpace,
  kHeightField,
  kMesh,
  kCompound
};
// Terrain: shapes of many triangles, which may touch a body along several normals at once.
inline bool is_terrain(ShapeType type) {
  return type == ShapeType::kHeightField || type == ShapeType::kMesh;
}
// Shapes only static bodies may have: the ground and terrain.
inline bool is_static_only(ShapeType type) {
  return type == ShapeType::kHalfSpace || is_terrain(type);
}
// Shapes whose pairs may touch along several manifolds at once: terrain and compounds.
inline bool makes_many_manifolds(ShapeType type) {
  return is_terrain(type) || type == ShapeType::kCompound;
}
const char* shape_type_name(ShapeType type);

struct MassProperties {
  double mass = 0;                     // kg
  Vec3 center_of_mass = Vec3::Zero();  // m, shape frame
  Mat3 inertia = Mat3::Zero();         // kg m^2, about the centre of mass, shape-frame axes
};

struct ShapeState;  // everything a shape is made of, for the state format (physics/src)
class Compound;     // physics/compound.h

class Shape {
 public:
  // Validates the definition; the message names the bad field ("half_extents[1]: must be > 0").
  static Result<Shape> create(const ShapeDef& def);

  ShapeType type() const { return type_; }
  double radius() const { return radius_; }                   // sphere, capsule
  double half_height() const { return half_height_; }         // capsule
  const Vec3& half_extents() const { return half_extents_; }  // box
  // The polyhedron of a box or hull; null for the other shapes.
  const ConvexPolyhedron* polyhedron() const { return polyhedron_.get(); }
  // The heightfield of a heightfield shape; null for the other shapes.
  const HeightField* height_field() const { return height_field_.get(); }
  // The mesh of a mesh shape; null for the other shapes.
  const TriangleMesh* mesh() const { return mesh_.get(); }
  // The parts of a compound shape (physics/compound.h); null for the other shapes.
  const Compound* compound() const { return compound_.get(); }

  // Bounds in the shape frame; infinite for a half-space. A heightfield's reach down to its base.
  Aabb local_bounds() const;
  double volume() const;  // m^3; infinite for a half-space, a heightfield and a mesh
  // Mass properties for a uniform density (kg/m^3).
  MassProperties mass_properties(double density) const;
  // A length that sets the scale of numerical tolerances: the largest half extent (a
  // heightfield's: its larger spacing, the size of its features; a mesh's: its longest triangle
  // edge; a compound's: its smallest part's).
  double size() const;
  // m: the radius of the largest sphere about the shape's origin that fits inside it (the
  // smallest half extent of a box); a body moving less than this per step cannot jump over a
  // wall of its own thickness. 0 when the origin is outside; infinite for a half-space; a
  // compound's is its thinnest part's (each part moving less than its own cannot jump a wall).
  double inner_radius() const { return inner_radius_; }
  // m: the largest distance of a point of the shape from its origin; infinite for a half-space.
  double outer_radius() const { return outer_radius_; }
  // The point of the shape farthest along `direction` (shape frame): of a compound, its parts'
  // convex hull's. Not for a half-space or terrain.
  Vec3 support(const Vec3& direction) const;
  // The same shape moved so that `offset` (shape frame) becomes the origin.
  Shape recentred(const Vec3& offset) const;

  // For World::save_state's bytes (physics/src/shape_state.h): what the shape is made of, and a
  // shape rebuilt from that when it may come from outside (a saved file, the network): every
  // number and index is checked, and the message names what is wrong.
  ShapeState state() const;
  static Result<Shape> from_state(const ShapeState& state);

 private:
  ShapeType type_ = ShapeType::kSphere;
  double radius_ = 0;
  double half_height_ = 0;
  Vec3 half_extents_ = Vec3::Zero();
  std::shared_ptr<const ConvexPolyhedron> polyhedron_;
  std::shared_ptr<const HeightField> height_field_;
  std::shared_ptr<const TriangleMesh> mesh_;
  std::shared_ptr<const Compound> compound_;
  double inner_radius_ = 0, outer_radius_ = 0;
  void update_radii();
  friend class Compound;
};

}  // namespace tumble
