// The state the world keeps of one joint (physics/include/physics/joint.h): its bodies, anchors
// and axes in the bodies' own frames, and the impulses it carried last, which warm-start the next
// step. Private to the engine, as body_state.h is.
#pragma once

#include <cstdint>

#include "physics/joint.h"
#include "physics/math.h"

namespace tumble {

// Body b of a joint held by the world itself.
inline constexpr std::uint32_t kWorldAnchor = UINT32_MAX;

struct Joint {
  JointKind kind = JointKind::kBall;
  std::uint32_t a = 0, b = kWorldAnchor;  // body slots
  // The anchors from each body's centre of mass in its own axes; for the world, a world point.
  Vec3 local_a = Vec3::Zero(), local_b = Vec3::Zero();
  // A hinge's axis in each body's axes (unit); for the world, world axes.
  Vec3 axis_a = Vec3::UnitZ(), axis_b = Vec3::UnitZ();
  // A fixed joint's rotation of b relative to a when made: q_a^-1 q_b.
  Quat relative = Quat::Identity();
  // A direction perpendicular to the axis in each body's axes (world for the world), the same
  // direction when made: a hinge's angle and a ball's twist are measured between them.
  Vec3 reference_a = Vec3::UnitX(), reference_b = Vec3::UnitX();
  double length = 0;  // a distance joint's
  bool collide_connected = false;
  JointLimit limit;
  JointMotor motor;
  JointSpring spring;
  double max_swing = 3.141592653589793;
  double friction = 0;  // JointDef::friction
  // Warm start, world: the impulse at the anchors (N s, on b; a takes the opposite), the angular
  // impulse (N m s, on b), and a distance joint's along its rod.
  Vec3 linear_impulse = Vec3::Zero(), angular_impulse = Vec3::Zero();
  double axial_impulse = 0;
  // Along the free coordinate (N s or N m s): the limit's, the motor's and the spring's; a ball's
  // swing cone's about the lean.
  double limit_impulse = 0, motor_impulse = 0, spring_impulse = 0, swing_impulse = 0;
  // The friction's (N m s or N s): a ball's angular impulse (world, on b), or along a hinge's or
  // slider's coordinate in x.
  Vec3 friction_impulse = Vec3::Zero();
  // What the last step's impulses were spread over (s): a substep, or the step (pgs).
  double impulse_time = 0;
};

struct JointSlot {
  Joint joint;
  std::uint32_t generation = 0;
  bool alive = false;
};

}  // namespace tumble
