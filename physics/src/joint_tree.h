// The direct solve of an island's joints when they form no loop: the rows every joint must hold
// (joint_solver.h, JointEquations) solved together and exactly, in time linear in the joints
// (Baraff 1996, "Linear-time dynamics using Lagrange multipliers", SIGGRAPH). Gauss-Seidel passes
// a chain's load one link a sweep, so a chain with a heavy end stretches (1:1000 by centimetres);
// solved directly, with the joints' geometric stiffness (joint_tree.cc), it holds whatever the
// masses.
//
// The system is the block matrix [M J^T; J 0] over the jointed moving bodies and the joints, a
// tree (a forest) when the joints close no loop: each body and each joint a node, a joint joined
// to its moving bodies. Eliminating every node after its children fills nothing in. Statics and
// the world are no nodes: their velocity is fixed. Limits, motors and springs stay Gauss-Seidel
// rows swept before it.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "contact_solver.h"
#include "joint_solver.h"

namespace tumble {

class JointTree {
 public:
  // The forest of the island's joints (indices into `rows`); false when the joints close a loop
  // (the island keeps Gauss-Seidel). `body_count`: the step's solver bodies. Keeps its memory
  // from one island to the next.
  bool build(std::span<const std::uint32_t> joints, std::span<const JointRow> rows,
             std::span<const SolverBody> bodies, std::size_t body_count);

  // Whether the velocity system holds any body's stiffness: each solve then also damps the stiff
  // modes a little (the stiffness is in the masses, not in the velocities' right side), so a
  // second sweep changes the velocities.
  bool stiffened() const { return stiffened_; }
  // The rows changed (a motor joins the solve again): the next sweep factors afresh.
  void forget_velocity_factors() { velocities_factored_ = false; }
  // Velocities that hold every joint's rows at the sweep's targets (JointTarget); the impulses
  // are added to the joints' warm start. Returns the largest velocity change it made.
  double solve_velocities(std::span<JointRow> rows, std::span<SolverBody> bodies,
                          std::span<const Pose> poses, const JointTarget& target);
  // Moves the bodies onto every joint's rows, to first order (one Newton step; velocities
  // untouched): a position pass. Without `refactor`, with the rows of the pass before (a chord
  // step: the passes after the first correct errors a million times smaller, through rows that
  // barely turned); the first pass after a move must refactor. With `velocity_substep` > 0 (and
  // no motor in the tree: its row is a velocity row alone), the pass's factors serve the velocity
  // sweeps too where no body takes stiffness for a substep of that length (their systems are then
  // the same: the same rows and masses; the passes after it move the bodies by a millionth of
  // this one's correction).
  void solve_positions(std::span<const JointRow> rows, std::span<SolverBody> bodies,
                       std::span<Pose> poses, bool refactor, double velocity_substep = 0);

  // The exact solver's use of the tree (exact_joints.h), with the velocity factors of the last
  // solve_velocities: whether a body is one of the tree's;
  bool holds(std::uint32_t body) const {
    return body < node_of_body_.size() && node_of_body_[body] != kNone;
  }
  // the change of the tree's bodies' velocities when the impulses act on some of them (linear,
  // then angular; world axes) while every joint's rows keep their rates: the response the LCP's
  // rows see through the joints. False where the factors give none (a degenerate joint).
  struct BodyImpulse {
    std::uint32_t body;  // a solver index the tree holds
    Eigen::Matrix<double, 6, 1> impulse;
  };
  bool respond(std::span<const BodyImpulse> impulses);
  // After respond: a body's velocity change (linear, angular);
  Eigen::Matrix<double, 6, 1> change_of(std::uint32_t body) const {
    return nodes_[node_of_body_[body]].rhs;
  }
  // and the response given to the bodies (as velocities, or as the push-out's pseudo-velocities)
  // with, for velocities, the joints' impulses added to their rows.
  void apply_response(std::span<JointRow> rows, std::span<SolverBody> bodies, bool pseudo) const;

 private:
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  static constexpr std::uint32_t kNone = UINT32_MAX;

  // A body (its solver index) or a joint (its index into the rows).
  struct Node {
    bool is_joint = false;
    std::uint32_t index = 0;
    std::uint32_t parent = kNone;  // a node
    // The block of this node's rows and the parent's columns (a joint's Jacobian on its parent
    // body, or a body's Jacobian columns of its parent joint, transposed).
    Mat6 to_parent = Mat6::Zero();
    Mat6 pivot = Mat6::Zero();  // the node's diagonal block once its children are eliminated
    Mat6 reach = Mat6::Zero();  // pivot^-1 to_parent, once factored
    Vec6 rhs = Vec6::Zero();
    // The edge to the parent carries three rows or fewer (a ball or distance joint's): the
    // joint's pivot is then its 3x3 corner and -1s, and the blocks' last three rows (a joint's)
    // or columns (a body's) are zero, so the products take their first three alone.
    bool narrow = false;
    Mat3 inertia = Mat3::Zero();  // a body's, world axes (fixed for the step, as its inverse)
    // A body's share of its joints' geometric stiffness, times h^2 (linear, angular), added to
    // its mass in the velocity solve.
    Mat3 linear_stiffness = Mat3::Zero(), angular_stiffness = Mat3::Zero();
    Vec3 longest_lever = Vec3::Zero();  // from the body's centre to its farthest joint anchor
  };

  // Fills the joints' rows (equations(k) for joint node k) and the bodies' masses (with their
  // stiffness for velocities) and eliminates the children into their parents.
  template <class Equations>
  void factor(std::span<const JointRow> rows, std::span<const SolverBody> bodies, bool velocities,
              Equations equations);
  // With the factors: the right side (a body's M v for velocities, else 0; a joint's rows'
  // targets(k)) solved, the solution per node in rhs.
  template <class Targets>
  void solve(std::span<const SolverBody> bodies, bool velocities, Targets targets);
  // The elimination's forward and back passes over the right side in the nodes' rhs.
  void substitute();
  bool solution_finite() const;
  // SHAKE's second iterate of the curvature targets in kept_targets_, where it converges
  // (solve_velocities); the bodies' velocities are left as they were.
  template <class Rates>
  void take_second_targets(std::span<const JointRow> rows, std::span<SolverBody> bodies,
                           std::span<const Pose> poses, const JointTarget& target, Rates rates_of);
  // Sets each body's stiffness (Node) for a substep of h (joint_tree.cc: why and how much);
  // whether any body has some.
  bool set_geometric_stiffness(std::span<const JointRow> rows, std::span<const SolverBody> bodies,
                               std::span<const Pose> poses, double h);

  // What a forest is built from: each joint's row, its bodies, and whether it holds rows and
  // each body moves.
  struct JointEnds {
    std::uint32_t row, a, b;
    std::uint8_t flags;
    bool operator==(const JointEnds&) const = default;
  };
  // The step's refresh of a forest built (or kept): inertias, motors, factors forgotten.
  void finish_build(std::span<const JointRow> rows, std::span<const SolverBody> bodies);

  std::vector<JointEnds> shape_, built_shape_;  // this build's, and the forest's in nodes_
  bool built_ = false;
  std::vector<Node> nodes_;                  // children before their parents
  std::vector<Node> reordered_;              // the build's renumbering (kept: no allocation)
  std::vector<std::uint32_t> node_of_body_;  // by solver index: kNone if none
  std::vector<std::uint32_t> bodies_used_;   // solver indices whose node_of_body_ is set
  std::vector<JointEquations> equations_;    // by node, for joints
  // A substep's targets for its sweeps before the move (solve_velocities).
  std::vector<Eigen::Matrix<double, 6, 1>> kept_targets_;
  // The targets of SHAKE's second iterate, and the bodies' velocities it starts from.
  std::vector<Eigen::Matrix<double, 6, 1>> second_targets_, held_velocities_;
  bool velocities_factored_ = false;  // since the last move
  bool stiffened_ = false;
  bool has_motors_ = false;     // a joint with a motor: its row joins the velocity system
  bool targets_taken_ = false;  // since the last move
  // For building: each node's neighbours and the visit.
  std::vector<std::uint32_t> first_edge_, next_edge_, edge_to_, pending_, parent_of_, order_;
  std::vector<std::uint8_t> visited_;
};

}  // namespace tumble
