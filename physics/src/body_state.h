// The state the world keeps of one body. Private to the engine: users read bodies through
// BodyView and save them through World::save_state, so that a field can be added, split off or
// packed differently without touching anything outside physics/src.
#pragma once

#include <cmath>
#include <cstdint>

#include "physics/body.h"
#include "physics/limits.h"
#include "physics/math.h"
#include "physics/shape.h"
#include "physics/status.h"

namespace tumble {

// The state of one body. The shape is re-centred on the centre of mass, so `position` is the
// centre of mass (for a hull it differs from BodyDef::position by the rotated centroid offset).
struct Body {
  Shape shape;
  BodyType type = BodyType::kDynamic;
  double mass = 0, inverse_mass = 0;  // kg, 1/kg (0 for static)
  Mat3 inertia_body = Mat3::Zero();   // kg m^2, body frame, about the centre of mass
  Mat3 inverse_inertia_body = Mat3::Zero();
  Mat3 inverse_inertia_world = Mat3::Zero();  // kept current with the orientation
  Vec3 position = Vec3::Zero();               // m, centre of mass
  Quat orientation = Quat::Identity();
  Vec3 linear_velocity = Vec3::Zero();   // m/s
  Vec3 angular_velocity = Vec3::Zero();  // rad/s, world frame
  double friction = 0.5;
  double restitution = 0;
  double gravity_scale = 1;
  double linear_damping = 0, angular_damping = 0;  // 1/s
  Vec3 force = Vec3::Zero(), torque = Vec3::Zero();  // N, N m; world, held
  CollisionFilter filter;
  // The inertia is a multiple of the identity (sphere, cube): no gyroscopic torque.
  bool spherical_inertia = false;
  // A symmetric top (two principal moments equal, as a capsule's, a cylinder's or a square
  // bar's): its axis of symmetry in body axes, and (I_across - I_along) / I_across, the rate its
  // angular velocity turns about that axis per rad/s of spin along it. Its free rotation then has
  // a closed form (integrate.cc). A zero axis: no such top (or a sphere). Worked out from the
  // inertia (refresh_symmetric_top), not stored in a saved state.
  Vec3 symmetric_axis = Vec3::Zero();
  double symmetric_spin_ratio = 0;
  void refresh_symmetric_top();
  // Sleeping: how long the body has stayed near where its quiet time began (s; 0 starts it anew),
  // that pose (the sleep anchor), whether it sleeps, and the island it fell asleep with (its
  // lowest slot), which wakes as one.
  double sleep_timer = 0;
  Vec3 sleep_anchor_position = Vec3::Zero();
  Quat sleep_anchor_orientation = Quat::Identity();
  bool asleep = false;
  std::uint32_t sleep_island = 0;

  bool is_static() const { return type == BodyType::kStatic; }
  bool is_kinematic() const { return type == BodyType::kKinematic; }
  bool is_dynamic() const { return type == BodyType::kDynamic; }
  // Dynamic and awake: what the solver moves.
  bool is_moving() const { return type == BodyType::kDynamic && !asleep; }
  // A kinematic body with a velocity: the step moves it, and what it touches stays awake. One at
  // rest costs what a static body costs.
  bool carries() const {
    return type == BodyType::kKinematic &&
           !(linear_velocity.isZero(0) && angular_velocity.isZero(0));
  }
  Pose pose() const { return {position, orientation}; }
  // Anything beyond gravity and contacts: a held force or torque, another gravity, damping. Kept
  // as a flag (refresh_own_forces after any of them changes): the step asks it of every body in
  // every substep, and a world without pays one byte's test.
  bool own_forces = false;
  bool has_own_forces() const { return own_forces; }
  void refresh_own_forces() {
    own_forces = gravity_scale != 1 || linear_damping != 0 || angular_damping != 0 ||
                 !force.isZero(0) || !torque.isZero(0);
  }
  // The most the body's velocity can change in a second from what acts on it alone, gravity's
  // (|gravity| given), the held force and torque's (at the shape's outer radius): m/s^2.
  double pull(double gravity) const {
    if (!has_own_forces()) return gravity;
    return std::abs(gravity_scale) * gravity + inverse_mass * force.norm() +
           (inverse_inertia_world * torque).norm() * shape.outer_radius();
  }
  void update_world_inertia() {
    const Mat3 r = orientation.toRotationMatrix();
    inverse_inertia_world = r * inverse_inertia_body * r.transpose();
  }
};

// The gravity scale and dampings a body may take; the message names the field. BodyDef's
// validation, World::check_motion and a restored state's check all ask this.
Status check_own_forces(double gravity_scale, double linear_damping, double angular_damping);

// What a kinematic body refuses: anything that would move it but its velocity (a held force or
// torque, a gravity scale, damping); the message names the field.
Status check_kinematic_motion(const Vec3& force, const Vec3& torque, double gravity_scale,
                             double linear_damping, double angular_damping);

// Builds a body from a validated definition.
Result<Body> make_body(const BodyDef& def);

// Checks a built body against the limits; the message names the field and the limit
// ("shape.radius: 1e+18 m is above limits.max_size (100000 m)").
Status check_limits(const Body& body, const WorldLimits& limits);

}  // namespace tumble
