// Rigid bodies: the definition a body is made from and its id. How the world stores a body is its
// own business (physics/src/body_state.h); read a body through World::body (body_view.h).
#pragma once

#include <compare>
#include <cstdint>

#include "physics/math.h"
#include "physics/shape.h"
#include "physics/status.h"

namespace tumble {

// An opaque handle. A removed body's id never comes back to life: its slot is reused under a new
// generation.
struct BodyId {
  std::uint32_t index = UINT32_MAX;
  std::uint32_t generation = 0;

  bool is_valid() const { return index != UINT32_MAX; }
  auto operator<=>(const BodyId&) const = default;
};

enum class BodyType : std::uint8_t {
  kStatic,     // infinite mass, never moves
  kDynamic,    // moved by forces and contacts
  kKinematic,  // infinite mass, moved only by the velocity the user gives it (a platform, a
               // conveyor, a door): it pushes dynamic bodies and is never pushed back
};

// Which bodies collide: two do when each one's layers meet the other's mask (Bullet's group and
// mask). Bodies the filter keeps apart are never handed to the narrow phase. The default is in
// layer 1 and meets every layer.
struct CollisionFilter {
  std::uint32_t layers = 1;         // the layers the body is in, one bit each
  std::uint32_t mask = 0xFFFFFFFF;  // the layers it collides with
  bool collides_with(const CollisionFilter& other) const {
    return (layers & other.mask) != 0 && (other.layers & mask) != 0;
  }
  bool operator==(const CollisionFilter&) const = default;
};

// The most |gravity_scale|, and the most damping (1/s), a body takes.
inline constexpr double kMaxGravityScale = 1e3;
inline constexpr double kMaxDamping = 1e6;

struct BodyDef {
  ShapeDef shape = BoxDef{};
  BodyType type = BodyType::kDynamic;
  // Pose of the shape frame, world coordinates: m, and a quaternion body -> world. A quaternion
  // within 1e-3 of unit length is normalised; any other is refused.
  Vec3 position = Vec3::Zero();
  Quat orientation = Quat::Identity();
  Vec3 linear_velocity = Vec3::Zero();   // m/s, of the centre of mass
  Vec3 angular_velocity = Vec3::Zero();  // rad/s, world frame
  // Mass: kg. When 0 the mass comes from `density` (kg/m^3) and the shape's volume.
  double mass = 0;
  double density = 1000;
  double friction = 0.5;   // Coulomb coefficient, >= 0
  double restitution = 0;  // in [0, 1]
  // The world's gravity times this acts on the body (0 floats, -1 falls up); |x| <= 1e3.
  double gravity_scale = 1;
  // Damping, 1/s, in [0, 1e6]: each step takes v to v / (1 + c h) (implicit Euler of dv/dt = -c v:
  // a velocity decays as e^-ct to first order and never reverses, however stiff).
  double linear_damping = 0, angular_damping = 0;
  // A force (N, world) and torque (N m, world, about the centre of mass) held on the body every
  // step until changed (World::set_motion). Dynamic bodies only; bounded so that one longest step
  // (limits.max_time_step) from rest stays within the speed limits.
  Vec3 force = Vec3::Zero();
  Vec3 torque = Vec3::Zero();
  CollisionFilter filter = {};
};

// Checks a definition without creating anything; the message names the field.
Status validate(const BodyDef& def);

// What a body made from `def` weighs: its mass (kg; 0 for a static body), its inertia about the
// centre of mass in the shape's axes (kg m^2; zero for a static body), and where that centre lies
// in the shape's frame (m). Fails as World::create_body would for an invalid definition.
Result<MassProperties> body_mass_properties(const BodyDef& def);

}  // namespace tumble
