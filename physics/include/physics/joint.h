// Joints: constraints between two bodies, or a body and the world, solved with the contacts of
// their island. What is defined here is given in world coordinates at the moment the joint is
// made (the bodies' poses then); the world keeps each anchor and axis in its body's own frame, so a
// joint holds whatever the bodies do afterwards.
#pragma once

#include <compare>
#include <cstdint>

#include "physics/body.h"
#include "physics/math.h"
#include "physics/status.h"

namespace tumble {

// An opaque handle, generational as BodyId: a removed joint's id never comes back to life.
struct JointId {
  std::uint32_t index = UINT32_MAX;
  std::uint32_t generation = 0;

  bool is_valid() const { return index != UINT32_MAX; }
  auto operator<=>(const JointId&) const = default;
};

enum class JointKind : std::uint8_t {
  kBall,      // the anchor points coincide; any rotation (spherical joint)
  kHinge,     // the anchor points coincide; rotation about `axis` alone (revolute joint)
  kFixed,     // the anchor points coincide and the relative rotation stays as made (weld)
  kDistance,  // the two anchor points stay `length` apart (a rigid rod with ball ends)
};

struct JointDef {
  JointKind kind = JointKind::kBall;
  BodyId a;  // a body of the world, dynamic or static
  BodyId b;  // another body, or an invalid id for the world itself
  // m, world: where the joint is (ball, hinge, fixed); for a distance joint, the end on body a.
  Vec3 anchor = Vec3::Zero();
  // m, world: a distance joint's end on body b (or a point fixed in the world).
  Vec3 anchor_b = Vec3::Zero();
  // A hinge's axis, world; any length above 1e-9 (it is normalised).
  Vec3 axis = Vec3::UnitZ();
  // A distance joint's length (m); 0 takes the anchors' distance when the joint is made.
  double length = 0;
  // Whether the two bodies still collide with each other (most joints want them not to).
  bool collide_connected = false;
};

// Checks what can be checked without a world (finite values, an axis, the length); the message
// names the field ("axis: must not be zero").
Status validate(const JointDef& def);

}  // namespace tumble
