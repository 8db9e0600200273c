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

// What a body made from `def` weighs: its mass (kg; 0 for a static body), its inertia about the
// centre of mass in the shape's axes (kg m^2; zero for a static body), and where that centre lies
// in the shape's frame (m). Fails as World::create_body would for an invalid definition.
Result<MassProperties> body_mass_properties(const BodyDef& def);

}  // namespace tumble
