// Asking the world what is there, between steps: ray casts (World::cast_ray, cast_rays,
// cast_ray_all), shape casts (cast_shape, cast_shapes), overlaps and closest points. A query reads the world and changes nothing; batches spread over the world's
// threads and give the same answers for any thread count.
#pragma once

#include <cstdint>

#include "physics/body.h"
#include "physics/math.h"
#include "physics/shape.h"
#include "physics/status.h"

namespace tumble {

// m: the longest ray a query may ask for (a ray across the whole world of limits.max_coordinate).
inline constexpr double kMaxRayLength = 1e10;

struct RayCast {
  Vec3 origin = Vec3::Zero();     // m, world
  Vec3 direction = Vec3::UnitX(); // world; any length but zero (it is normalised)
  double max_distance = 1e3;      // m along the direction, > 0 and <= kMaxRayLength
  // The layers it meets: a body is hit when its collision layers share a bit with this mask
  // (CollisionFilter::layers).
  std::uint32_t mask = 0xFFFFFFFF;
};

struct RayHit {
  BodyId body;             // invalid: no hit
  double distance = 0;     // m from the origin along the (normalised) direction
  double fraction = 0;     // distance / max_distance, in [0, 1]
  Vec3 point = Vec3::Zero();   // m, world
  Vec3 normal = Vec3::Zero();  // unit, world, the surface's outward normal at the point
  bool hit() const { return body.is_valid(); }
};

// Checks a ray; the message names the field ("direction: must not be zero").
Status validate(const RayCast& ray);

// The point of a body's surface nearest to a point (World::closest_point).
struct ClosestPoint {
  bool found = false;          // false: the body is farther than the query's max_distance
  Vec3 point = Vec3::Zero();   // m, world, on the body's surface
  Vec3 normal = Vec3::Zero();  // unit, world, the surface's outward normal there
  double distance = 0;         // m from the query point; negative when it is inside the body
};

// A shape placed in the world, to find the bodies it overlaps (World::overlap): a trigger volume,
// a gripper's reach.
struct OverlapQuery {
  ShapeDef shape = SphereDef{};  // any shape a body may have but a half-space
  Pose pose;                      // of the shape's frame, world
  std::uint32_t mask = 0xFFFFFFFF;  // as RayCast::mask
};

// A shape swept along a straight path without turning, to find the first body it meets: a
// gripper closing in, a character's step, a thick ray.
struct ShapeCast {
  ShapeDef shape = SphereDef{};      // any shape a body may have but a half-space
  Pose pose;                          // of the shape's frame at the start, world
  Vec3 translation = Vec3::Zero();    // m, world: the sweep; |translation| <= kMaxRayLength
  std::uint32_t mask = 0xFFFFFFFF;    // as RayCast::mask
};

// m: a shape cast's answer is the first place along its sweep where the shape comes within this
// of a body (conservative advancement stops there; docs/COLLISION.md, "Queries").
inline constexpr double kShapeCastTolerance = 1e-6;
// Advancement steps a shape cast takes against one body at most (each a narrow-phase call).
inline constexpr int kShapeCastIterations = 64;

struct ShapeHit {
  BodyId body;                 // invalid: no hit
  double fraction = 0;         // of the translation at first contact, in [0, 1]; 0 if it starts
                               // touching or overlapping the body
  Vec3 point = Vec3::Zero();   // m, world: the contact point on the body's surface there
  Vec3 normal = Vec3::Zero();  // unit, world: the body's outward normal there (against the sweep)
  // False when advancement against the body nearest in the sweep hit its bound
  // (kShapeCastIterations) before coming within the tolerance: nothing is met before `fraction`,
  // but the contact may lie a little beyond it.
  bool converged = true;
  bool hit() const { return body.is_valid(); }
};

// Checks where a query places its shape: a finite position and a unit orientation (within 1e-3,
// normalised where used); the message names the field.
Status validate_placement(const Pose& pose);

// Checks a shape cast; the message names the field ("translation: must be finite").
Status validate(const ShapeCast& cast);

}  // namespace tumble
