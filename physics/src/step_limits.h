// The step's last guard: what the solver and integrator computed for a body becomes its state
// only within the world's limits. Inputs are checked against the same limits before they enter
// the world, so this only acts on runaway cases (a huge impulse from a degenerate contact, a body
// falling for days); each case is counted in StepStats instead of being spread silently.
#pragma once

#include <cstdint>

#include "body_state.h"
#include "physics/limits.h"

namespace tumble {

enum StepGuard : std::uint8_t {
  kStepTaken = 0,
  // A non-finite pose or velocity: the body keeps its pose from before the step, at rest.
  kStepNonFinite = 1,
  // Faster than max_linear_speed or max_angular_speed: slowed to it, direction kept.
  kStepSlowed = 2,
  // Beyond max_coordinate: held at the edge, its velocity out of the world removed.
  kStepAtEdge = 4,
};

// Stores the step's result in `body` (and its world inertia); returns what the guard did.
std::uint8_t take_step_result(Body* body, const Pose& pose, const Vec3& linear_velocity,
                              const Vec3& angular_velocity, const WorldLimits& limits);

}  // namespace tumble
