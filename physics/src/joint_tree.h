// The direct solve of an island's joints when they form no loop: the rows every joint must hold
// (joint_solver.h, JointEquations) solved together and exactly, in time linear in the joints
// (Baraff 1996, "Linear-time dynamics using Lagrange multipliers", SIGGRAPH). Gauss-Seidel passes
// a chain's load one link a sweep, so a chain with a heavy end stretches (1:1000 by centimetres);
// solved directly, with the joints' geometric stiffness (joint_tree.cc), it holds whatever the
// masses.
//
// Baraff's system [M J^T; J 0] over the moving bodies and the joints is a tree (a forest) when
// the joints close no loop. It is solved here in the joints' impulses alone: J W J^T lambda = b
// (W the bodies' inverse masses, known in closed form). Two joints meet in that matrix only where
// they share a body, so the joints of one body form a clique, and the cliques a tree; eliminating
// each joint after the joints below it (its children's) fills nothing in. The blocks are the
// joints' rows (3 for a ball or distance joint, up to 6), not the bodies' 6 x 6 masses: a chain
// of ball joints is block tridiagonal in 3 x 3 blocks. Statics and the world are no bodies of
// it: their velocity is fixed. Limits, motors and springs stay Gauss-Seidel rows swept before it.
#pragma once

#include <Eigen/Core>
#include <atomic>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "contact_solver.h"
#include "joint_solver.h"
#include "joint_terms.h"

namespace tumble {

// What a forest looks up by the step's solver index (each body's place in it, each body's turn
// over a move): as long as the step's bodies, so one per thread, lent to the forest of the island
// the thread solves (JointTree::attach) rather than one per forest.
struct JointTreeIndex {
  std::vector<std::uint32_t> node_of_body;  // its tree body in the attached forest, or UINT32_MAX
  std::vector<Quat> turns;                  // JointTree::set_turns
};

// The check of refactor_stiffened by the tests (test_joint_tree_refactor.cc). With `mode` kCount,
// `partial` counts the partial factorings, so the check knows the path ran; with kWhole too, each
// of them forms and eliminates every joint of the same rows instead, as factoring them whole
// does, and must give the same bits. Process-wide: set it only where no other world steps. Off
// (kOff), the step only reads `mode`, a line no thread writes.
struct JointTreeRefactorCheck {
  enum Mode : int { kOff, kCount, kWhole };
  static inline std::atomic<int> mode{kOff};
  static inline std::atomic<std::uint64_t> partial{0};
};

class JointTree {
 public:
  static constexpr std::uint32_t kNone = UINT32_MAX;

  // The thread's index, for one island's solve: build() and everything after it use it, and
  // detach() leaves it as it found it (every entry kNone) for the thread's next island.
  void attach(JointTreeIndex* index) { index_ = index; }
  void detach();

  // The forest of the island's joints (indices into `rows`); false when the joints close a loop
  // or a body holds more than 16 of them (JointTree::Hub; the island keeps Gauss-Seidel).
  // `body_count`: the step's solver bodies. Keeps its memory, and the same joints between the
  // same bodies keep the forest, from one step to the next.
  bool build(std::span<const std::uint32_t> joints, std::span<const JointRow> rows,
             std::span<const SolverBody> bodies, std::size_t body_count);

  // Whether the velocity system holds any body's stiffness: each solve then also damps the stiff
  // modes a little (the stiffness is in the masses, not in the velocities' right side), so a
  // second sweep changes the velocities.
  bool stiffened() const { return stiffened_; }
  // Substeps whose takes of a conserving island's curvature targets (JointTarget::conserving)
  // stopped at kMostTakes or stopped contracting before they settled, since the last call.
  std::uint32_t take_limit_hits() { return std::exchange(take_limit_hits_, 0); }
  // The rows changed (a motor joins the solve again): the next sweep factors afresh.
  void forget_velocity_factors() { velocities_factored_ = false; }
  // Velocities that hold every joint's rows at the sweep's targets (JointTarget); the impulses
  // are added to the joints' warm start. Returns the largest velocity change it made.
  // `terms`: the island's joints' terms at these poses (prepare_joint_terms), by row, whose
  // anchors it reads rather than working them out again.
  double solve_velocities(std::span<JointRow> rows, std::span<SolverBody> bodies,
                          std::span<const Pose> poses, const JointTarget& target,
                          std::span<const JointPoseTerms> terms);
  // Moves the bodies onto every joint's rows, to first order (one Newton step; velocities
  // untouched): a position pass. Without `refactor`, with the rows of the pass before (a chord
  // step: the passes after the first correct errors a million times smaller, through rows that
  // barely turned); the first pass after a move must refactor. With `velocity_substep` > 0 (and
  // no motor in the tree: its row is a velocity row alone), the pass's factors may serve the
  // velocity sweeps too, where no body takes stiffness for a substep of that length (their
  // systems are then the same: the same rows and masses; the passes after it correct about the
  // square of this one's correction): settle_velocity_factors says after the last pass.
  // With `bounds`, a refactoring pass holds the limits and cones the poses are past by more than
  // `bound_slack` (position_equations). Returns the largest error it corrected (its targets'
  // largest, m or rad; infinity where the solve gave no finite answer and nothing moved): a Newton
  // pass leaves about its square.
  double solve_positions(std::span<const JointRow> rows, std::span<SolverBody> bodies,
                         std::span<Pose> poses, bool refactor, double velocity_substep = 0,
                         bool bounds = true, double bound_slack = 0);
  // Whether the last refactoring pass's factors are to serve the velocity sweeps (pending the
  // settle after the passes).
  bool velocity_factors_pending() const { return share_pending_; }
  // After a move's position passes: whether the factors of the pass given velocity_substep h serve
  // the velocity sweeps (no body takes stiffness at the poses the passes left). Where some body
  // does, and `keep_stiffness`, the stiffness worked out here is the next velocity factoring's
  // (the sweeps that follow meet these poses and impulses; the exact solver's substep clears the
  // impulses first, and does not keep it), which then factors again from the pass's factors only
  // the joints it changes (refactor_stiffened).
  // `terms`: as for solve_velocities, at the poses the passes left (or empty).
  void settle_velocity_factors(std::span<const JointRow> rows, std::span<const SolverBody> bodies,
                               std::span<const Pose> poses, double h, bool keep_stiffness,
                               std::span<const JointPoseTerms> terms = {});

  // The exact solver's use of the tree (exact_joints.h), with the velocity factors of the last
  // solve_velocities: whether a body is one of the tree's;
  bool holds(std::uint32_t body) const {
    return body < index_->node_of_body.size() && index_->node_of_body[body] != kNone;
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
    return tree_bodies_[index_->node_of_body[body]].result;
  }
  // and the response given to the bodies (as velocities, or as the push-out's pseudo-velocities)
  // with, for velocities, the joints' impulses added to their rows.
  void apply_response(std::span<JointRow> rows, std::span<SolverBody> bodies, bool pseudo) const;

 private:
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  // Past it a hub's blocks (half its joints squared, 576 bytes each) would outgrow the rest of
  // the tree's memory several times over, and their elimination grow with the cube.
  static constexpr std::uint32_t kMostHubJoints = 16;

  // The forest as built: a body (its solver index) or a joint (its index into the rows), each
  // joint joined to its moving bodies, children before their parents.
  struct Node {
    bool is_joint = false;
    std::uint32_t index = 0;
    std::uint32_t parent = kNone;  // a node
  };
  // A moving body of the forest.
  struct TreeBody {
    std::uint32_t index = 0;      // solver index
    Mat3 inertia = Mat3::Zero();  // world axes (fixed for the step, as its inverse)
    // Its share of its joints' geometric stiffness, times h^2 (linear, angular), added to its
    // mass in the velocity solve.
    Mat3 linear_stiffness = Mat3::Zero(), angular_stiffness = Mat3::Zero();
    Vec3 longest_lever = Vec3::Zero();  // from the body's centre to its farthest joint anchor
    double longest_arm = 0, second_arm = 0;  // the two longest levers' lengths
    // The adjugate of its inverse inertia (fixed for the step), and set_geometric_stiffness's
    // bound on its rho and whether the bound left it to the full test (`weighed`).
    Mat3 inverse_inertia_adjugate = Mat3::Zero();
    double rho_bound = 0;
    bool weighed = false;
    // The inverse of the mass the last factoring used (with stiffness: `stiff`; else the
    // body's inverse mass and inertia).
    bool stiff = false;
    double inverse_mass = 0;
    Mat3 linear_inverse = Mat3::Zero(), angular_inverse = Mat3::Zero();
    Vec6 base = Vec6::Zero();    // the velocity (or move) before the joints act
    Vec6 result = Vec6::Zero();  // and after
  };
  // A joint of the forest, in elimination order (children before parents). Its rows are padded
  // to a width of 3, 5 or 6 (a padded row: 1 on the diagonal, 0 elsewhere), so that every block
  // has a fixed size: a ball's 3, a hinge's or slider's 5 (and a ball's with a bound of a position
  // pass), a fixed joint's 6 (padding a hinge to 6 cost the tree a tenth more instructions).
  struct TreeJoint {
    std::uint32_t row = 0;                         // index into the rows
    std::uint32_t body_a = kNone, body_b = kNone;  // tree bodies; kNone: static or the world
    int width = 3;
    std::uint8_t bounds = 0;  // the bound rows of the last position factoring (joint_solver.h)
    // Where its later neighbours are: the hub of its parent body, and its place there (kNone:
    // it has none).
    std::uint32_t hub = kNone, place = 0;
    // Those later neighbours (laters of them) as the substitution walks them: hub_members_ and
    // pairs_ from these indices on (a hub's pairs of one member with the later ones lie together).
    std::uint32_t laters = 0, first_later = 0, first_later_pair = 0;
    Mat6 pivot = Mat6::Zero();  // J W J^T over both bodies, less its children's; then inverted
    // W J^T on each body: a unit of each row's impulse as the body's velocity change.
    Mat6 response_a = Mat6::Zero(), response_b = Mat6::Zero();
    Vec6 rhs = Vec6::Zero();  // the right side, then the rows' impulses
  };
  // A moving body's joints (its children's joints in elimination order, then its parent joint):
  // every two of them share the body, so their block of J W J^T is not zero. Eliminating one
  // changes only the blocks among the others of the same hub: no fill (the joint graph of a tree
  // is a tree of such cliques).
  struct Hub {
    std::uint32_t body = 0;  // tree body
    std::uint32_t first_member = 0, members = 0, first_pair = 0;
  };
  // The block of J W J^T between two joints of a hub (rows of the earlier), and once factored
  // its `reach`: the earlier's inverse pivot times the block.
  struct HubPair {
    Mat6 block = Mat6::Zero();
    Mat6 reach = Mat6::Zero();
  };
  std::uint32_t pair_index(const Hub& hub, std::uint32_t i, std::uint32_t j) const {
    return hub.first_pair + i * (2 * hub.members - i - 1) / 2 + (j - i - 1);
  }
  const Mat6& jacobian(std::size_t k, bool side_b) const {
    return side_b ? equations_[k].on_b : equations_[k].on_a;
  }

  // Fills the joints' rows (equations(k, &row's equations) for joint k) and the bodies' inverse
  // masses (with their stiffness for velocities), forms J W J^T and factors it.
  template <class Equations>
  void factor(std::span<const SolverBody> bodies, bool velocities, Equations equations);
  // The bodies' inverse masses for a factoring (with their stiffness for velocities), and joint
  // k's response and diagonal block J W J^T from its rows (equations_) and those masses.
  void set_masses(std::span<const SolverBody> bodies, bool velocities);
  void form_pivot(std::size_t k);
  // The hubs' blocks and the elimination; with OnlyChanged, only of the joints changed_ marks
  // (refactor_stiffened), the others' factors kept.
  template <int Every, bool OnlyChanged>
  void eliminate();
  // The velocity sweeps' factoring from the last position pass's (settle_velocity_factors kept
  // its stiffness): only the joints the stiffness changes are factored again.
  void refactor_stiffened(std::span<const SolverBody> bodies);
  // With the factors: the joints' impulses that bring each joint's rows from the bodies' base
  // velocities (or 0) to targets(k), and the bodies' results.
  template <class Targets>
  void solve(bool from_base, Targets targets);
  // The elimination's forward and back passes over the joints' rhs (with_width's `Every`).
  template <int Every>
  void substitute_with();
  bool solution_finite() const;
  // Each of the joints' bodies' turn over a move of h at its velocity (rotation_quaternion(h w);
  // identity for a static body) in the index's turns, by solver index: the targets' arithmetic,
  // once a body rather than once a joint end.
  void set_turns(std::span<const JointRow> rows, std::span<const SolverBody> bodies, double h);
  // set_turns a joint at a time: start_turns, then turn_bodies_of each joint whose turns are read
  // (a body shared by two joints is turned once).
  void start_turns();
  void turn_bodies_of(const JointRow& row, std::span<const SolverBody> bodies, double h);
  // The base velocities for a velocity solve: the bodies' own, or with stiffness (M+K)^-1 M v.
  void set_velocity_base(std::span<const SolverBody> bodies);
  // A velocity solve's answer taken: the joints' impulses added to their rows, the bodies'
  // velocities set to the results. Returns the largest velocity change.
  double take_solution(std::span<JointRow> rows, std::span<SolverBody> bodies);
  // The joints' impulses of a solve without stiffness, at rate zero (motors at their speed),
  // added to the joints' rows and the bodies' velocities: loads for set_geometric_stiffness.
  template <class VelocityEquations>
  void learn_loads(std::span<JointRow> rows, std::span<SolverBody> bodies,
                   VelocityEquations velocity_equations);
  // SHAKE's next iterate of the curvature targets in kept_targets_ (solve_velocities), into
  // second_targets_: the kept targets solved (the solution left in the joints' and bodies'
  // results; the bodies' velocities as they were) and the targets taken again from the
  // velocities found. How far they moved: relative to the kept ones, and times the substep. Once
  // the relative move is past `refused_above` (the iterate will not be taken), the joints left
  // are not visited: the ratio returned is then past it too, and second_targets_ incomplete.
  struct Retake {
    double ratio = 0, move = 0;
  };
  template <class Rates>
  Retake take_targets_again(std::span<const JointRow> rows, std::span<SolverBody> bodies,
                            std::span<const Pose> poses, const JointTarget& target, Rates rates_of,
                            double refused_above, std::span<const JointPoseTerms> terms);
  // Sets each body's stiffness (TreeBody) for a substep of h (joint_tree.cc: why and how much);
  // whether any body has some.
  // With `terms` (by row; empty where they are not at these poses), their anchors are read.
  bool set_geometric_stiffness(std::span<const JointRow> rows, std::span<const SolverBody> bodies,
                               std::span<const Pose> poses, double h,
                               std::span<const JointPoseTerms> terms = {});

  // What a forest is built from: each joint's row, its bodies, and whether it holds rows and
  // each body moves.
  struct JointEnds {
    std::uint32_t row, a, b;
    std::uint8_t flags;
    bool operator==(const JointEnds&) const = default;
  };
  // The forest's joints, bodies and hubs from the ordered nodes; false where a hub holds more
  // than kMostHubJoints (its blocks grow with the square of its joints, its elimination with the
  // cube: a body holding a thousand joints would need half a million blocks).
  bool number_forest(std::span<const JointRow> rows, std::span<const SolverBody> bodies);
  // The step's refresh of a forest built (or kept): inertias, motors, factors forgotten.
  void finish_build(std::span<const JointRow> rows, std::span<const SolverBody> bodies);

  std::vector<JointEnds> shape_, built_shape_;  // this build's, and the forest's
  bool built_ = false;
  std::vector<Node> nodes_;                  // children before their parents
  std::vector<Node> reordered_;              // the build's renumbering (kept: no allocation)
  std::vector<TreeJoint> joints_;            // elimination order
  std::vector<TreeBody> tree_bodies_;
  std::vector<Hub> hubs_;
  std::vector<std::uint32_t> hub_members_;   // joints
  std::vector<std::uint8_t> member_side_b_;  // whether the hub's body is the member's b
  std::vector<HubPair> pairs_;
  JointTreeIndex* index_ = nullptr;         // attach()
  std::vector<std::uint32_t> bodies_used_;  // solver indices the forest's bodies are
  std::vector<JointEquations> equations_;   // by joint
  // A substep's targets for its sweeps before the move (solve_velocities).
  std::vector<Eigen::Matrix<double, 6, 1>> kept_targets_;
  // The targets of SHAKE's second iterate, and the bodies' velocities it starts from.
  std::vector<Eigen::Matrix<double, 6, 1>> second_targets_, held_velocities_;
  std::vector<std::uint8_t> turned_;  // by tree body: its turn set for the take under way
  bool velocities_factored_ = false;  // since the last move
  bool stiffened_ = false;
  // 3 where every joint of the last factoring has 3 rows (a chain of balls), else 0: the solves
  // then take that width for every joint without asking (with_width).
  int every_width_ = 0;
  // settle_velocity_factors: a pass's factors that may serve the sweeps, and the bodies'
  // stiffness worked out for the next velocity factoring.
  // Where stiffness is kept, the factors are still that pass's (refactor_stiffened).
  bool share_pending_ = false, stiffness_kept_ = false;
  std::vector<std::uint8_t> changed_;  // by joint: refactor_stiffened's
  // The largest error the last refactoring position pass corrected, and whether its factors are
  // the next stiffened velocity factoring's start (settle_velocity_factors).
  double factored_correction_ = 0;
  bool factors_kept_ = false;
  bool has_motors_ = false;     // a joint with a motor: its row joins the velocity system
  // A joint the step has not yet solved (just made: no impulse to tell its load): the first
  // velocity factoring learns the loads first (solve_velocities).
  bool loads_unknown_ = false;
  bool targets_taken_ = false;  // since the last move
  std::uint32_t take_limit_hits_ = 0;
  // For building: each node's neighbours and the visit.
  std::vector<std::uint32_t> first_edge_, next_edge_, edge_to_, pending_, parent_of_, order_;
  std::vector<std::uint32_t> numbered_, child_count_;
  std::vector<std::uint8_t> visited_;
};

}  // namespace tumble
