#include "step_limits.h"

#include <cmath>

namespace tumble {

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
  if (const double v = linear_velocity.norm(); v > limits.max_linear_speed) {
    body->linear_velocity *= limits.max_linear_speed / v;
    guard |= kStepSlowed;
  }
  if (const double w = angular_velocity.norm(); w > limits.max_angular_speed) {
    body->angular_velocity *= limits.max_angular_speed / w;
    guard |= kStepSlowed;
  }
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
