#include "step_limits.h"

#include <cmath>
#include <limits>

namespace tumble {
namespace {

// Scales a velocity down to the speed limit, measured as check_speeds measures it (speed_of).
// Scaling by max / |v| can round to a hair above the limit (a restored state then failed its own
// check after one step, as the snapshot fuzz found), so a last shave of a few ulps follows.
bool hold_speed(Vec3* velocity, double max_speed) {
  const double speed = speed_of(*velocity);
  if (!(speed > max_speed)) return false;
  *velocity *= max_speed / speed;
  for (int shave = 0; shave < 4 && speed_of(*velocity) > max_speed; ++shave)
    *velocity *= 1 - 4 * std::numeric_limits<double>::epsilon();
  return true;
}

}  // namespace

std::uint8_t take_step_result(Body* body, const Pose& pose, const Vec3& linear_velocity,
                              const Vec3& angular_velocity, const WorldLimits& limits) {
  if (!is_finite(pose.position) || !is_finite(pose.orientation) || !is_finite(linear_velocity) ||
      !is_finite(angular_velocity)) {
    body->linear_velocity.setZero();
    body->angular_velocity.setZero();
    return kStepNonFinite;
  }
  std::uint8_t guard = kStepTaken;
  body->position = pose.position;
  body->orientation = pose.orientation;
  body->linear_velocity = linear_velocity;
  body->angular_velocity = angular_velocity;
  if (hold_speed(&body->linear_velocity, limits.max_linear_speed)) guard |= kStepSlowed;
  if (hold_speed(&body->angular_velocity, limits.max_angular_speed)) guard |= kStepSlowed;
  for (int k = 0; k < 3; ++k) {
    const double edge = limits.max_coordinate;
    if (std::abs(body->position[k]) <= edge) continue;
    const double side = body->position[k] > 0 ? 1 : -1;
    body->position[k] = side * edge;
    if (body->linear_velocity[k] * side > 0) body->linear_velocity[k] = 0;
    guard |= kStepAtEdge;
  }
  body->update_world_inertia();
  return guard;
}

}  // namespace tumble
