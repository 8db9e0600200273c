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
  kDistance,  // the two anchor points stay `length` apart (a rod with ball ends), or in `limit`
  kSlider,    // no rotation; the anchors slide along `axis` alone (prismatic joint)
};

// A joint's free coordinate: a hinge's angle (rad, b's turn about the axis from how it was made,
// in (-pi, pi]), a slider's offset (m, b's anchor from a's along the axis), a distance joint's
// length (m), a ball's twist (rad, about its axis). Fixed joints have none.

// Bounds on the free coordinate: hinge and ball twist within [-pi, pi], distance within [0, inf).
// lower == upper locks it.
struct JointLimit {
  bool enabled = false;
  double lower = 0, upper = 0;
};

// Drives the free coordinate's speed (rad/s or m/s) with at most max_force (N m or N): hinges
// and sliders.
struct JointMotor {
  bool enabled = false;
  double speed = 0;
  double max_force = 0;
};

// Pulls the free coordinate toward `target` with the stiffness (N m/rad or N/m) and damping
// (N m s/rad or N s/m) given, implicitly (a stiff spring does not blow up): hinges, sliders, and
// distance joints, whose spring rests at `length` (target unused, 0).
struct JointSpring {
  bool enabled = false;
  double target = 0;
  double stiffness = 0;
  double damping = 0;
};

struct JointDef {
  JointKind kind = JointKind::kBall;
  BodyId a;  // a body of the world, dynamic or static
  BodyId b;  // another body, or an invalid id for the world itself
  // m, world: where the joint is (ball, hinge, fixed); for a distance joint, the end on body a.
  Vec3 anchor = Vec3::Zero();
  // m, world: a distance joint's end on body b (or a point fixed in the world).
  Vec3 anchor_b = Vec3::Zero();
  // A hinge's or slider's axis, a ball's twist axis (for max_swing and limit), world; any length
  // above 1e-9 (it is normalised).
  Vec3 axis = Vec3::UnitZ();
  // A distance joint's length (m); 0 takes the anchors' distance when the joint is made.
  double length = 0;
  // Whether the two bodies still collide with each other (most joints want them not to).
  bool collide_connected = false;
  JointLimit limit;
  JointMotor motor;
  JointSpring spring;
  // A ball's swing cone: the most b's axis may lean from a's (rad, in (0, pi]; pi: free).
  double max_swing = 3.141592653589793;
  // The joint's own friction: the most torque (N m: ball, hinge) or force (N: slider) it gives
  // against its free motion (a ball's whole relative turn, a hinge's angle, a slider's offset),
  // as a zero-speed motor of that bound would; a joint held below it sticks. 0: none. Fixed and
  // distance joints have none. Jolt's swing-twist friction torque, MuJoCo's frictionloss.
  double friction = 0;
};

// What a joint does at the bodies' present poses: its free coordinate (JointLimit's comment;
// 0 for fixed joints) and that coordinate's rate, and the reaction the joint gave over the last
// step, on body b (a took the opposite): force (N) and torque about b's anchor (N m), world.
// `effort` is the part along the free coordinate (N m or N), positive where it pushes the
// coordinate up: motor, spring, friction and limit together (a distance joint's: its ends pushed
// apart, so a hanging rod reads negative).
struct JointReading {
  double position = 0;
  double speed = 0;
  double effort = 0;
  Vec3 force = Vec3::Zero();
  Vec3 torque = Vec3::Zero();
};

// Checks what can be checked without a world (finite values, an axis, the length); the message
// names the field ("axis: must not be zero").
Status validate(const JointDef& def);
// Values no joint needs, beyond which doubles would overflow in the solver's products: forces,
// stiffnesses and dampings up to 1e20 (SI), lengths and offsets within twice `max_coordinate`.
// World::check_joint also bounds anchors by the world's max_coordinate and motor speeds by its
// speed limits.
inline constexpr double kMaxJointForce = 1e20;

// The parts checked for a kind (a running joint's motor and spring may change).
Status validate(JointKind kind, const JointLimit& limit);
Status validate(JointKind kind, const JointMotor& motor);
Status validate(JointKind kind, const JointSpring& spring);
Status validate_friction(JointKind kind, double friction);

}  // namespace tumble
