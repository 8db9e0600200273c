// Joint constraints in the iterative solvers: each joint's rows solved as one block (the point of
// a ball, hinge or fixed joint as three rows at once, a hinge's two angular rows at once, a fixed
// joint's three), warm-started from the last step: the sweeps before a move ask for velocities
// that end the move on the joint, those after it for velocities the joint allows (JointTarget),
// and what the move's linearised turns leave is projected out of the positions. A soft joint (the
// contacts' spring) damped a pendulum: at 170 degrees its period came out 0.6-15% short.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>

#include "contact_solver.h"
#include "joint_state.h"
#include "physics/math.h"

namespace tumble {
namespace joint_detail {
struct Anchors;  // joint_geometry.h
}

// A joint as the step solves it: its bodies by solver index (kWorldAnchor: the world) and a
// copy of what it needs, impulses included (stored back to the world's joint after the solve).
struct JointRow {
  Joint joint;
  std::uint32_t a = 0, b = kWorldAnchor;
  std::uint32_t slot = 0;  // the world's joint slot
  // The direct solve (joint_tree.h) holds the motor as a sixth row of the joint's equations, not
  // a Gauss-Seidel row beside it, while its force stays within its bound; past it, the motor's
  // impulse is held at the bound for the rest of the substep (motor_at_bound).
  bool motor_in_tree = false;
  bool motor_at_bound = false;
};

struct JointPoseTerms;  // joint_terms.h: what the visits below read of the poses

// Applies the row's impulses to its bodies at their present poses: the warm start.
void warm_start_joint(const JointRow& row, std::span<SolverBody> bodies,
                      std::span<const Pose> poses, const JointPoseTerms& terms);

// What a sweep asks of a joint: with a move of h ahead (h > 0), velocities under which the move
// opens no error (the turns' curvature included, which the velocities' first order misses; at
// most most_speed m/s or rad/s for it); with h = 0, velocities the joint allows now, rigidly.
// The error a joint has is closed by the position passes after each move, never through the
// velocities: closing it there too overshot in Gauss-Seidel and threw a chain with a 100 times
// heavier end kilometres.
// The first is SHAKE's position step, the second RATTLE's velocity projection (Andersen 1983,
// "Rattle: a velocity version of the Shake algorithm"): together they keep a pendulum's energy.
// `substep` is the time the coming move takes, before the move or after it: the limits'
// speculative margins and the springs and motors use it.
struct JointTarget {
  double h = 0;
  double most_speed = 0;
  double substep = 0;
  // The island's energy is its joints' alone (no contacts, drives or bounds to take any): the
  // direct solve's curvature targets are iterated until they settle (joint_tree.cc).
  bool conserving = false;
  // Whether a Gauss-Seidel visit (solve_joint) holds the joint's own rows at the move's curvature
  // or at rate zero (its drives and bounds keep h either way). The curvature keeps energy only
  // where the visit's answer is the joint's whole solve (SerialIsland::sweep says where).
  bool curvature = true;
};

// The rows a joint must hold exactly (its point, axes, rotation, a rod's length, a slider's line;
// not its limits, motor or spring), linearised at the present poses: `rows` rows of a Jacobian on
// each body (6 columns: linear, then angular; world) and what each row's rate must be (`target`),
// or, for positions, minus each row's error. Rows beyond `rows` are zero. For the direct solve of
// joint trees (joint_tree.h).
struct JointEquations {
  using Vector = Eigen::Matrix<double, 6, 1>;
  int rows = 0;
  // Whether the first three rows are a point's (a ball's, a hinge's, a fixed joint's): on a,
  // [-I, [r_a]x]; on b, [I, -[r_b]x] (JointTree's products take that shape).
  bool point_rows = false;
  // Whether the rows after the point's (all of them, without a point) turn the bodies alone, their
  // linear columns zero (a hinge's axis rows, a cone or a twist limit): JointTree sets it where it
  // factors, and its products skip those columns.
  bool turning_rest = false;
  // Whether rows 0-2 of on_a and on_b hold a point's linear blocks, -I and I, from the last
  // writer of those rows: a point's next rows then write its cross blocks alone (half the stores
  // of a chain's equations; every writer of those rows clears it).
  bool point_linear_held = false;
  Eigen::Matrix<double, 6, 6> on_a = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 6> on_b = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> target = Eigen::Matrix<double, 6, 1>::Zero();
};
// For velocities, with the sweep's target (a move ahead: the rates that end it on the joint).
// `anchors`, where given, the joint's anchors at these poses (JointPoseTerms: the same bits).
void velocity_equations(JointEquations* equations, const JointRow& row,
                        std::span<const SolverBody> bodies, std::span<const Pose> poses,
                        const JointTarget& target, const joint_detail::Anchors* anchors = nullptr);
// Their targets alone (velocity_equations' target), without building the rows; `turns`, where
// given, each body's rotation_quaternion(target.h w) by solver index (the same answer, without
// a sine and cosine a joint end).
JointEquations::Vector velocity_targets(const JointRow& row, std::span<const SolverBody> bodies,
                                        std::span<const Pose> poses, const JointTarget& target,
                                        const Quat* turns = nullptr,
                                        const joint_detail::Anchors* anchors = nullptr);
// Whether the equations' last row is the joint's motor (JointRow::motor_in_tree).
bool motor_row(const JointRow& row, const JointEquations& equations);
// For positions: target = minus the error. With `bounds`, the joint's cone and limit that the
// poses are past (or a locked limit) follow as rows of their own, held where they are met for the
// pass, and *bounds says which (kConeRow, kLimitRow): a position pass of the direct solve then
// corrects the bounds and the joint's own rows at once, where a separate pass of the bounds and
// one of the rows each undid part of the other. With a `bound_slack` (m or rad), only those past
// by more (a locked limit too).
inline constexpr std::uint8_t kConeRow = 1, kLimitRow = 2;
void position_equations(JointEquations* equations, const JointRow& row,
                        std::span<const SolverBody> bodies, std::span<const Pose> poses,
                        std::uint8_t* bounds = nullptr, double bound_slack = 0);
// Their targets alone (position_equations' target), with the bound rows `bounds` (as
// position_equations chose them for the factoring these targets are solved with).
JointEquations::Vector position_targets(const JointRow& row, std::span<const SolverBody> bodies,
                                        std::span<const Pose> poses, std::uint8_t bounds = 0);
// Adds the equations' impulses (one per row, on b; a takes the opposite) to the joint's warm
// start, in the same terms as the Gauss-Seidel rows keep them.
void add_equation_impulses(JointRow& row, const JointEquations& equations,
                           const Eigen::Matrix<double, 6, 1>& impulses);

// The joint's springs, motors and limits alone (joint_axial.h): what a sweep does besides the
// direct solve of the joint's own rows. Without `bounds`, its one-sided limits and cone are left
// to the exact solver (joint_axial.h, bound_rows).
double solve_joint_drives(JointRow& row, std::span<SolverBody> bodies, std::span<const Pose> poses,
                          const JointTarget& target, const JointPoseTerms& terms,
                          bool bounds = true);

// One Gauss-Seidel visit of the joint's rows. Returns the largest velocity change it gave (m/s).
double solve_joint(JointRow& row, std::span<SolverBody> bodies, std::span<const Pose> poses,
                   const JointTarget& target, const JointPoseTerms& terms);

// One nonlinear Gauss-Seidel visit of the joint's position error after the bodies moved (Catto's
// position solve, Box2D 2.x): the bodies are moved and turned back onto the joint through their
// inverse masses and inertias, velocities untouched, and their motion since the step start is
// kept current for the contacts' separations.
void correct_joint_position(const JointRow& row, std::span<SolverBody> bodies,
                            std::span<Pose> poses);

// The joint's reading (joint.h) at the given poses and velocities (b: the world's, at rest, when
// the joint holds to the world), from the impulses it stored.
JointReading read_joint(const Joint& joint, const Pose& pose_a, const Pose& pose_b,
                        const SolverBody& a, const SolverBody& b);

// How far the joint is from holding, at the given poses: m for the anchors (or the length), rad
// for the axes or rotation, whichever is larger; a limit's or cone's overrun counts. For tests
// and reports.
double joint_error(const Joint& joint, const Pose& pose_a, const Pose& pose_b);

}  // namespace tumble
