// What a world accepts. Every body, change of motion, impulse and restored state is checked
// against these before anything changes, and the step keeps every body within them, so that the
// world never holds a value that double precision or the solvers cannot carry (a spin of 1e308
// rad/s turns into NaN in one step; a sphere of radius 1e18 m needs more grid cells than memory).
#pragma once

#include <span>
#include <string_view>

#include "physics/body.h"
#include "physics/body_view.h"
#include "physics/status.h"

namespace tumble {

struct WorldLimits {
  // m: |x|, |y| and |z| of every body's centre of mass (and of a static plane's origin). At 1e9 m
  // doubles still resolve 0.1 µm.
  double max_coordinate = 1e9;
  // m: a body's smallest dimension (sphere or capsule radius, box half extent, half the thinnest
  // side of a hull's box) and its largest (the farthest point of the shape from its centre).
  // Together they bound the size ratio of any two bodies, and the aspect ratio of one, to 1e10.
  double min_size = 1e-5;
  double max_size = 1e5;
  // kg: a dynamic body's mass; the mass ratio of any two bodies is at most max_mass / min_mass.
  double min_mass = 1e-15;
  double max_mass = 1e15;
  double max_linear_speed = 1e5;   // m/s, of the centre of mass
  double max_angular_speed = 1e6;  // rad/s
  double max_time_step = 1;        // s, one call of World::step
};

// s: the shortest step a world takes. A shorter one advances nothing worth the cost (a step of
// 5e-324 s leaves the clock where it was, and a server stepping it would spin for nothing).
inline constexpr double kMinTimeStep = 1e-6;
// dt finite and within [kMinTimeStep, limits.max_time_step]; the message starts with "dt: ".
Status check_time_step(double dt, const WorldLimits& limits);

// Each limit by the name scene files and command lines use ("max_size").
struct LimitField {
  std::string_view name;
  double WorldLimits::*value;
};
std::span<const LimitField> limit_fields();

// Checks the limits themselves; the message names the field ("max_size: must be > min_size").
Status validate(const WorldLimits& limits);

// Everything World::create_body checks of one definition (validate, the shape, its mass) and the
// body it would make against the limits, without a world; the message names the field and the
// limit ("shape.radius: 1e+18 m is above limits.max_size (100000 m)").
Status check_definition(const BodyDef& def, const WorldLimits& limits);
// The same limits for a body of a world (after a step, say).
Status check_limits(BodyView body, const WorldLimits& limits);

// The length of a velocity as the limits measure it: without overflow for any finite vector, and
// the same bits wherever it is computed (Eigen's stableNorm sums in an order that depends on the
// vector's alignment, so a speed held at the limit in the step read a hair above it elsewhere).
double speed_of(const Vec3& velocity);

// Checks velocities a body would take ("linear_velocity: ... above limits.max_linear_speed").
Status check_speeds(const Vec3& linear_velocity, const Vec3& angular_velocity,
                    const WorldLimits& limits);

// Checks a held force and torque on a body of that inverse mass and world inverse inertia.
Status check_held_forces(const Vec3& force, const Vec3& torque, double inverse_mass,
                         const Mat3& inverse_inertia_world, const WorldLimits& limits);

}  // namespace tumble
