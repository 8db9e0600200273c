#include "continuous.h"

#include <algorithm>
#include <cmath>

#include "rotation.h"

namespace tumble {

Pose pose_at(const SweptMotion& motion, double t) {
  Pose pose;
  pose.position = motion.start.position + t * motion.translation;
  pose.orientation =
      t == 0 ? motion.start.orientation : rotated(motion.start.orientation, t * motion.rotation);
  return pose;
}

ImpactResult time_of_impact(const Shape& a, const SweptMotion& motion_a, const Shape& b,
                            const SweptMotion& motion_b, double target, double tolerance,
                            int max_iterations) {
  ImpactResult result;
  const Vec3 translation = motion_b.translation - motion_a.translation;
  // Rotation lets a point run ahead of its centre by at most |angle| times its radius.
  const double turning = motion_a.rotation.norm() * motion_a.outer_radius +
                         motion_b.rotation.norm() * motion_b.outer_radius;
  const double reach = translation.norm() + turning;  // the most the gap can close in the step
  CollisionSettings settings;
  settings.feature_slack = 0;
  ContactManifold manifold;
  double t = 0;
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    result.iterations = iteration + 1;
    // Pairs farther apart than they can close in the rest of the step produce no manifold.
    settings.margin = reach * (1 - t) + target;
    collide(a, pose_at(motion_a, t), b, pose_at(motion_b, t), settings, &manifold);
    if (manifold.count == 0) return result;  // kMiss
    const double gap = -manifold.depth;
    result.normal = manifold.normal;
    if (gap <= target + tolerance) {
      result.status = t == 0 ? ImpactStatus::kTouchingAtStart : ImpactStatus::kHit;
      result.t = t;
      return result;
    }
    // The nearest parts' normal bounds how fast a compound's other parts close only along it: a
    // compound's gap closes at most at the whole relative speed.
    const double along = a.type() == ShapeType::kCompound || b.type() == ShapeType::kCompound
                             ? translation.norm()
                             : -manifold.normal.dot(translation);
    const double closing = along + turning;
    if (closing <= 0) return result;  // moving apart along the normal, not turning: kMiss
    t += (gap - target) / closing;
    if (t >= 1) return result;
  }
  result.status = ImpactStatus::kIterationLimit;
  result.t = t;
  return result;
}

}  // namespace tumble
