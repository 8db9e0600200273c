// The rows along a joint's free coordinate (joint.h): springs, motors and limits on a hinge's
// angle, a slider's offset, a distance joint's length and a ball's twist, and a ball's swing cone.
// Limits are one-sided rows with a speculative margin (the coordinate may close the gap to its
// bound over the coming move, no more: Box2D v3's joint limits); a spring is the implicit
// spring-damper row (Catto, "Soft constraints", GDC 2011), stable however stiff; a motor's impulse
// is bounded by its force over the time it acts. Their errors are closed by the position passes,
// as the joints' own (joint_solver.h).
#pragma once

#include <numbers>

#include "joint_geometry.h"
#include "joint_terms.h"

namespace tumble {

// Whether it is a ball with a swing cone.
inline bool has_cone(const Joint& joint) {
  return joint.kind == JointKind::kBall && joint.max_swing < std::numbers::pi;
}
// Whether the joint has any of these rows (a spring, motor, limit or cone). (Inline: every sweep
// asks it of every joint.)
inline bool has_axial_rows(const Joint& joint) {
  return joint.spring.enabled || joint.motor.enabled || joint.limit.enabled || has_cone(joint) ||
         joint.friction > 0;
}

// The impulse the rows above gave along the free coordinate (limit, motor, spring, a hinge's or
// slider's friction); a rigid rod's, along it.
double impulse_along(const Joint& joint);

// The terms these rows read (joint_terms.h: the free coordinate, the cone, a ball's friction), b
// the world's body (joint_geometry.h, kWorldBody) and pose where world_b.
void prepare_axial_terms(const Joint& joint, const SolverBody& a, const SolverBody& b,
                         const Pose& pose_a, const Pose& pose_b, bool world_b,
                         JointPoseTerms* terms);

// Applies the free coordinate's rows' impulses from the last step: the warm start.
void warm_start_axial(const JointRow& row, joint_detail::JointBodies& j,
                      const JointPoseTerms& terms);

// One Gauss-Seidel visit of the rows (spring, motor, limit, cone, in that order: the limit has the
// last word). Without `bounds`, a limit that is not locked and the cone are left out (the exact
// solver holds them: bound_rows). Returns the largest velocity change it gave.
double solve_axial(JointRow& row, joint_detail::JointBodies& j, const JointTarget& target,
                   const JointPoseTerms& terms, bool bounds = true);

// A joint's one-sided rows as the exact solver's LCP holds them (a limit that is not locked, a
// ball's cone): the row, whose rate may close the gap over the coming move and no more, the gap
// (m or rad), and which bound it is. The limit's row is the side the coordinate is nearer, as the
// Gauss-Seidel visit takes it.
struct BoundRow {
  enum class Side : std::uint8_t { kLower, kUpper, kCone };
  joint_detail::AxialRow row;
  double gap = 0;
  Side side = Side::kLower;
};
// How many rows a joint may have here (for bounding an island's problem before building it).
int bound_row_count(const Joint& joint);
// The rows at the given poses (up to bound_row_count), into `out`; returns how many.
int bound_rows(const Joint& joint, const Pose& pose_a, const Pose& pose_b, bool world_b,
               BoundRow out[2]);
// Keeps the impulse (>= 0, along the row) the LCP found for a row as the joint's own.
void keep_bound_impulse(Joint& joint, BoundRow::Side side, double impulse);

// One position pass over the limits and the cone: a coordinate beyond its bound is put back on it
// through the inverse masses (velocities untouched).
void correct_axial(const Joint& joint, SolverBody* a, SolverBody* b, Pose* pose_a, Pose* pose_b);

// The reading (joint.h) from poses and velocities; the effort from the impulses stored.
JointReading read_axial(const Joint& joint, const Pose& pose_a, const Pose& pose_b,
                        const SolverBody& a, const SolverBody& b, bool world_b);

}  // namespace tumble
