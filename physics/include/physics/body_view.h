// A read-only look at one body of a world, got from World::body(id): what the server, the apps,
// the benchmarks and the tests read of a body, so that none of them depends on how the world
// stores its bodies (which may split a body's data by use, as Box2D v3 and Jolt do).
//
// A view shows the body as it is now: it follows steps, moves and impulses. It is good until
// bodies are created or removed (which may move storage); after that, ask the world again.
#pragma once

#include "physics/body.h"
#include "physics/math.h"
#include "physics/shape.h"

namespace tumble {

class World;
struct Body;  // the world's own storage (physics/src/body_state.h)

class BodyView {
 public:
  BodyView() = default;  // no body: false, and reading it is an error

  // False for the view of a stale or unknown id.
  explicit operator bool() const { return body_ != nullptr; }
  // So that `world.body(id)->position()` reads like the pointer it replaces.
  const BodyView* operator->() const { return this; }

  BodyType type() const;
  bool is_static() const;
  bool is_kinematic() const;
  bool asleep() const;
  // Dynamic and awake: what the step moves.
  bool is_moving() const;

  // The shape, re-centred on the centre of mass.
  const Shape& shape() const;
  double mass() const;          // kg; 0 for static and kinematic
  double inverse_mass() const;  // 1/kg; 0 for static and kinematic
  Mat3 inertia_body() const;    // kg m^2, body frame
  Mat3 inverse_inertia_world() const;
  double friction() const;
  double restitution() const;
  double gravity_scale() const;
  double linear_damping() const;   // 1/s
  double angular_damping() const;  // 1/s
  Vec3 force() const;               // N, world, held
  Vec3 torque() const;              // N m, world, about the centre of mass, held
  CollisionFilter filter() const;

  Vec3 position() const;  // m, centre of mass
  Quat orientation() const;
  Pose pose() const;
  Vec3 linear_velocity() const;   // m/s
  Vec3 angular_velocity() const;  // rad/s, world

 private:
  friend class World;
  explicit BodyView(const Body* body) : body_(body) {}
  const Body& body() const;

  const Body* body_ = nullptr;
};

}  // namespace tumble
