// Rigid bodies: the definition a body is made from, its id, and the state the engine keeps.
#pragma once

#include <compare>
#include <cstdint>
#include <memory>

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
  kStatic,   // infinite mass, never moves
  kDynamic,  // moved by forces and contacts
};

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
};

// Checks a definition without creating anything; the message names the field.
Status validate(const BodyDef& def);

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
  // The inertia is a multiple of the identity (sphere, cube): no gyroscopic torque.
  bool spherical_inertia = false;
  // Sleeping: how long the body has been slower than the sleep thresholds (s), whether it sleeps,
  // and the island it fell asleep with (its lowest slot), which wakes as one.
  double sleep_timer = 0;
  bool asleep = false;
  std::uint32_t sleep_island = 0;

  bool is_static() const { return type == BodyType::kStatic; }
  bool is_moving() const { return type == BodyType::kDynamic && !asleep; }
  Pose pose() const { return {position, orientation}; }
  void update_world_inertia() {
    const Mat3 r = orientation.toRotationMatrix();
    inverse_inertia_world = r * inverse_inertia_body * r.transpose();
  }
};

// Builds a body from a validated definition.
Result<Body> make_body(const BodyDef& def);

}  // namespace tumble
