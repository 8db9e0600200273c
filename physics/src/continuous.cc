#include "continuous.h"

#include <algorithm>
#include <cmath>

#include "narrow_phase.h"
#include "physics/compound.h"
#include "ray_shape.h"
#include "rotation.h"

namespace tumble {

Pose pose_at(const SweptMotion& motion, double t) {
  Pose pose;
  pose.position = motion.start.position + t * motion.translation;
  pose.orientation =
      t == 0 ? motion.start.orientation : rotated(motion.start.orientation, t * motion.rotation);
  return pose;
}

namespace {

// A pair touching at the start of the step is the contact solver's: its contacts, speculative as
// far as the body moves, keep it out. Against a convex shape they do; against a terrain they are
// planes of the triangles near the start, and a body that the solve sends far along the surface
// or turning fast (a box landing on one corner at 100 m/s pivots about it at 100 rad/s) can leave
// them behind and end under the surface: its centre crossed it, where no contact holds it any
// more (a mesh holds only bodies whose centre is in front of it). So where the body's centre
// crosses the terrain's surface in the step, it stops at the last time before (bisected) at which
// it is no deeper in than it started by more than `target`.
void stop_short_of_crossing(const Shape& a, const SweptMotion& motion_a, const Shape& b,
                            const SweptMotion& motion_b, double start_depth, double target,
                            double tolerance, double reach, int max_iterations,
                            ImpactResult* result) {
  const bool terrain_a = is_terrain(a.type());
  const Shape& body_shape = terrain_a ? b : a;
  const SweptMotion& body = terrain_a ? motion_b : motion_a;
  const SweptMotion& terrain = terrain_a ? motion_a : motion_b;
  // The body's and the terrain's poses at the start and the end (a static terrain's are one).
  const Pose body_start = body.start, body_end = pose_at(body, 1);
  const Pose frame_start = terrain.start;
  const Pose frame_end = terrain.translation.isZero() && terrain.rotation.isZero()
                             ? terrain.start
                             : pose_at(terrain, 1);
  // Where a point of the body's frame is, in the terrain's frame.
  const auto in_terrain = [](const Pose& frame, const Pose& at, const Vec3& local) {
    return Vec3(frame.orientation.conjugate() *
                (at.position + at.orientation * local - frame.position));
  };
  // The first time a centre's path (a segment from its start to its end) crosses the surface: the
  // body's, or each part's of a compound (a dumbbell's balls lie beside its centre).
  double crossing = 2;
  const auto cross = [&](const Vec3& local) {
    const Vec3 from = in_terrain(frame_start, body_start, local);
    const Vec3 path = in_terrain(frame_end, body_end, local) - from;
    const double length = path.norm();
    ShapeRayHit hit;
    // A centre that starts inside a heightfield's solid meets it at once: it is on its way out.
    if (length > 0 && ray_shape(terrain_a ? a : b, from, path / length, length, &hit) && hit.t > 0)
      crossing = std::min(crossing, hit.t / length);
  };
  if (body_shape.type() == ShapeType::kCompound) {
    for (const Compound::Part& part : body_shape.compound()->parts())
      cross(part.pose.position);
  } else {
    cross(Vec3::Zero());
  }
  if (crossing > 1) return;
  const double threshold = std::max(start_depth, 0.0) + target;
  CollisionSettings settings;
  settings.feature_slack = 0;
  settings.margin = target;
  ContactManifold manifold;
  double good = 0, bad = crossing;
  // Halved until no point moves more than the tolerance between the two: within it of where the
  // body would pass the threshold.
  for (int iteration = 0; iteration < max_iterations && (bad - good) * reach > tolerance;
       ++iteration) {
    const double t = 0.5 * (good + bad);
    collide(a, pose_at(motion_a, t), b, pose_at(motion_b, t), settings, &manifold);
    (manifold.count == 0 || manifold.depth <= threshold ? good : bad) = t;
  }
  // Stopped by the bound, `good` is still a time the body may stop at, and the bound is reported.
  result->status =
      (bad - good) * reach > tolerance ? ImpactStatus::kIterationLimit : ImpactStatus::kHit;
  result->t = good;
  result->in_contact = true;
}

}  // namespace

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
      if (t == 0 && is_terrain_pair(a, b))
        stop_short_of_crossing(a, motion_a, b, motion_b, -gap, target, tolerance, reach,
                               max_iterations, &result);
      return result;
    }
    // The nearest parts' normal bounds how fast a compound's other parts (a terrain's other
    // triangles) close only along it: their gap closes at most at the whole relative speed.
    const double along =
        is_many_manifold_pair(a, b) ? translation.norm() : -manifold.normal.dot(translation);
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
