// The step's solve and after: islands solved, positions corrected, results stored, sleep
// (the recipe, World::step, is step_recipe.cc).
#include <omp.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>

#include "auto_solver.h"
#include "exact_joints.h"
#include "exact_solver.h"
#include "integrate.h"
#include "joint_axial.h"
#include "parallel.h"
#include "physics/world.h"
#include "rotation.h"
#include "step_limits.h"
#include "step_scratch.h"
#include "step_stages.h"
#include "tall_stacks.h"
#include "world_slot.h"

namespace tumble {
namespace {

// Everything one island needs to advance, independent of every other island.
struct IslandContext {
  std::span<const std::uint32_t> bodies;
  std::span<const std::uint32_t> rows;
  std::span<const std::uint32_t> joints;  // indices into scratch.joint_rows
  // Its joint components (StepScratch::component_begin), and forests (StepScratch::joint_trees).
  std::uint32_t first_component, component_count;
  StepScratch& scratch;
  const WorldSettings& settings;
  std::span<const Body* const> body_of;  // by solver index
  // Its colours in StepScratch::colouring, [first, last): none where its contacts are swept row by
  // row, in the island's order.
  std::uint32_t first_colour = 0, last_colour = 0;
};

// How many manifolds island i has.
std::uint32_t manifolds_in(const StepScratch& s, std::size_t i) {
  return s.island_manifold_begin[i + 1] - s.island_manifold_begin[i];
}

// The velocity recipe of one island, written once for every solver and thread count. `run`
// carries each part out: over the island's rows in order on one thread (SerialIsland, which alone
// has the exact solver's LCP: exact islands are small), or colour by colour over the whole team
// (TeamIsland), which differs only in the order in which Gauss-Seidel visits the rows.
//   soft: per substep, gravity, warm start, iterations with the soft bias, move, relaxation
//         iterations without it (Catto's "Solver2D" soft step, 2024);
//   exact: gravity, one LCP (pgs when its answer is refused);
//   pgs:  gravity, warm start, iterations (then position correction, a later stage);
//   then the normal residual, the move (soft moved in its substeps) and restitution.
template <class Runner>
void advance_with(Runner& run, IslandReport* report, const SolverSettings& solver, double dt) {
  if (report->solver == IslandSolver::kSoft) {
    // Tall stacks take more substeps and a stiffer spring (tall_stacks.h), the rest the settings'.
    const bool stiffened = report->substeps > 0;
    const int substeps = stiffened ? report->substeps : solver.substeps;
    // A contact that would meet in the next step's first substep is met now: the last relaxation
    // sweep holds back its approach so that the gap left closes no faster than that substep, which
    // would pass part of a blow to the bodies behind before it lands.
    run.pass_impacts(dt + dt / substeps);
    const double hertz = stiffened ? report->contact_hertz : solver.contact_hertz;
    const double h = dt / substeps;
    // The spring may not be stiffer than the substep can follow (a quarter of its rate).
    const Softness soft =
        contact_softness(std::min(hertz, 0.25 / h), solver.contact_damping_ratio, h);
    for (int sub = 0; sub < substeps; ++sub) {
      run.integrate_velocities(h);
      // Exact with joints: one LCP instead of the sweeps; where it finds no answer, the sweeps go
      // on from what it left.
      bool exact = false, tried = false;
      if constexpr (Runner::kSolvesExact) {
        if (report->exact_joints) {
          tried = true;
          exact = run.exact_substep(h, sub > 0);
        }
      }
      if (!exact) {
        // From the second substep on, the impulse a row starts from is the last substep's whole.
        if (!tried) run.warm_start(sub > 0);
        for (int i = 0; i < solver.soft_iterations; ++i)
          if (run.sweep(&soft, h, (sub + i) % 2 == 1) <= solver.velocity_tolerance) break;
      }
      run.integrate_positions(h);
      run.refresh_separations();  // the relaxation sweeps see where the move left the bodies
      // The LCP has no bias to relax; but where its contacts act on jointed bodies, the velocities
      // are taken back onto the joints and contacts where the move left them (RATTLE's
      // projection, SerialIsland::relaxes_exact_substeps).
      if constexpr (Runner::kSolvesExact) {
        if (exact && !run.relaxes_exact_substeps()) continue;
      }
      for (int i = 0; i < solver.relax_iterations; ++i)
        if (run.sweep(nullptr, h, (sub + i) % 2 == 0) <= solver.velocity_tolerance) break;
    }
    run.finish(h);
    return;
  }
  run.pass_impacts(dt);
  run.integrate_velocities(dt);
  bool pgs = run.has_rows();
  if constexpr (Runner::kSolvesExact) {
    if (report->solver == IslandSolver::kExact && run.has_rows()) pgs = !run.solve_exact(dt);
  }
  if (pgs) {
    // A tall pgs island sweeps more and to the end (tall_stacks.h): sweeps stopped early leave
    // the compression it would buckle under.
    const bool tall = report->solver == IslandSolver::kPgs && report->pgs_iterations > 0;
    const int iterations = tall ? report->pgs_iterations : solver.iterations;
    const double tolerance = tall ? 0.0 : solver.velocity_tolerance;
    run.warm_start(false);
    for (int i = 0; i < iterations; ++i)
      if (run.sweep(nullptr, dt, i % 2 == 1) <= tolerance) break;
  }
  // After the move, as in the soft path: a body stopped by a speculative contact first lands,
  // then leaves with its bounce.
  run.finish(dt, [&] { run.integrate_positions(dt); });
}

// The island's bodies' velocities (or positions) advanced over h: by one thread (`solo`), or
// split over the team, which waits for all of them.
std::uint32_t team_integrate_velocities(const IslandContext& c, double h, bool solo) {
  std::uint32_t hits = 0;
  const std::int64_t n = static_cast<std::int64_t>(c.bodies.size());
  const auto integrate = [&](std::int64_t k) {
    const std::uint32_t body = c.bodies[k];
    if (!integrate_velocity(*c.body_of[body], c.scratch.poses[body].orientation, c.settings.gravity,
                            h, &c.scratch.bodies[body]))
      ++hits;
  };
  if (solo) {
    for (std::int64_t k = 0; k < n; ++k)
      integrate(k);
    return hits;
  }
#pragma omp for schedule(static) nowait
  for (std::int64_t k = 0; k < n; ++k)
    integrate(k);
  c.scratch.barrier.wait();
  return hits;
}

void team_integrate_positions(const IslandContext& c, double h, bool solo) {
  const std::int64_t n = static_cast<std::int64_t>(c.bodies.size());
  const auto integrate = [&](std::int64_t k) {
    const std::uint32_t body = c.bodies[k];
    integrate_position(h, &c.scratch.bodies[body], &c.scratch.poses[body]);
  };
  if (solo) {
    for (std::int64_t k = 0; k < n; ++k)
      integrate(k);
    return;
  }
#pragma omp for schedule(static) nowait
  for (std::int64_t k = 0; k < n; ++k)
    integrate(k);
  c.scratch.barrier.wait();
}

// Nonlinear Gauss-Seidel passes over an island's joints after each move (joint by joint, the
// settings' joint_position_passes; a tree's, these constants). Each pass takes a
// joint's error to second order in its size (a substep's drift is ~1e-5 m); a chain passes
// corrections along one link a pass, which the next moves' passes carry on. Solved directly
// (joint_tree.h), the first two passes are Newton steps and the last reuses the second's rows (on
// a chain of 20 dropped from the horizontal: 7e-6 m at worst, 1.8e-7 m refactoring every pass,
// for a fifth less time); the first also holds the limits and cones the poses are past (the
// second's rows are the velocity sweeps' too, which hold no bound). Where the first held none and
// corrected less than kNewtonAfter (the curvature targets leave a swinging chain ~1e-6 m open
// after a move), its rows are the sweeps' and the second is a chord step through them: it leaves
// what a Newton step would (3e-16 m against 2e-11 corrected on chain:100), the sweeps' rows are
// one pass old (turned by ~1e-5 rad, which the next move's passes close), and a factoring a
// substep is saved (chain:100, 4.86 M -> 4.42 M instructions a step). Not where the last sweeps
// stiffened the tree: its factors are not the sweeps' there, and a chord step through a heavy
// chain's ill-conditioned rows contracts less (1:1000, 5e-12 m -> 4e-9).
constexpr int kJointPositionPasses = 3;
constexpr int kJointRefactoredPasses = 2;
static_assert(kJointRefactoredPasses >= 1, "the first pass after a move refactors");
// Where contacts act through the trees, the move has no curvature targets (SerialIsland::
// tree_target) and opens each joint by its turn's curvature, ~w^2 r h^2: the first pass corrects
// millimetres where it corrected micrometres, and carries limbs past bounds it did not hold. There
// the second pass holds the bounds the poses are past by more than kLaterBoundSlack too (its
// factors then do not serve the sweeps), the third is a Newton step where the second corrected
// more than kNewtonAfter (a chord step's rows had turned too far: a chain of 20 dropped from level
// at dt 1/30 opened 2.7e-6 m against 3.6e-8), and a fourth, a chord step, follows. Measured on the
// pile of eight ragdolls at one substep (300 steps): the anchors' largest gap 2.3e-10 m, the
// bounds' mean 1.1e-7 and largest 2.6e-4 rad (with the targets and three passes: 2.3e-8 m,
// 1.1e-6 and 3.2e-3 rad; without the second's bounds, 1.7e-11 m, 6.1e-6 and 1.3e-2 rad).
constexpr double kLaterBoundSlack = 1e-6;  // m or rad
constexpr double kNewtonAfter = 1e-5;      // m or rad
// A Newton pass that corrected errors below this (m, or rad) left errors near their square over
// the joints' lever arms: under 1e-16 for levers down to a centimetre, below the poses' rounding.
constexpr double kSettledJointError = 1e-9;

// The visits of a coloured island's contacts, colour by colour (defined with the team's islands
// below).
template <class PackFn, class ManifoldFn>
double sweep_packs(StepScratch& s, std::uint32_t first, std::uint32_t last, bool backward,
                   bool solo, PackFn&& pack_fn, ManifoldFn&& manifold_fn, bool reduce = true);
template <class Fn>
double sweep_colours(StepScratch& s, std::uint32_t first, std::uint32_t last, bool backward,
                     bool solo, Fn&& fn, bool reduce = true);

// The contacts of a coloured island (its colours [first, last) in StepScratch::colouring), visited
// colour by colour: the colours' packs where the step sweeps them (contact_packs.h), else their
// manifolds' rows in the same order (the same bits). By the whole team, or by one thread (`solo`).
struct ColouredContacts {
  StepScratch& s;
  std::uint32_t first, last;
  bool solo;

  void warm_start(bool keep_last_substep, double kinematic_time) {
    sweep_packs(
        s, first, last, false, solo,
        [&](ContactPack& pack) {
          tumble::warm_start(pack, s.bodies, keep_last_substep, kinematic_time);
          return 0.0;
        },
        [&](const ManifoldRows& manifold) {
          tumble::warm_start(s.rows, s.cold_rows, std::span(manifold.ids, manifold.count), s.bodies,
                             keep_last_substep, kinematic_time);
          return 0.0;
        },
        false);
  }
  void refresh_separations(double kinematic_time) {
    sweep_packs(
        s, first, last, false, solo,
        [&](ContactPack& pack) {
          update_separations(pack, s.bodies, kinematic_time);
          return 0.0;
        },
        [&](const ManifoldRows& manifold) {
          update_separations(s.rows, std::span(manifold.ids, manifold.count), s.bodies,
                             kinematic_time);
          return 0.0;
        },
        false);
  }
  // The largest velocity change, on every thread.
  double sweep(const SolverSettings& settings, const Softness* soft, double h, bool backward) {
    return sweep_packs(
        s, first, last, backward, solo,
        [&](ContactPack& pack) { return solve_pack(pack, kAllLanes, s.bodies, settings, soft, h); },
        [&](const ManifoldRows& manifold) {
          return solve_manifold(s.rows, manifold, s.blocks, s.bodies, settings, soft, h);
        });
  }
  // The packs give the rows their impulses (for restitution and the pair records); returns the
  // normal residual, on every thread.
  double store_impulses(double h, double kinematic_time) {
    return sweep_packs(
        s, first, last, false, solo,
        [&](const ContactPack& pack) {
          tumble::store_impulses(pack, s.rows, s.cold_rows);
          double lane_residuals[kWideLanes];
          pack_residuals(pack, s.bodies, h, lane_residuals, kinematic_time);
          return *std::max_element(std::begin(lane_residuals), std::end(lane_residuals));
        },
        [&](const ManifoldRows& manifold) {
          return normal_residual(s.rows, std::span(manifold.ids, manifold.count), s.bodies, h,
                                 kinematic_time);
        });
  }
  void apply_restitution(const SolverSettings& settings) {
    sweep_colours(
        s, first, last, false, solo,
        [&](std::span<const std::uint32_t> ids) {
          tumble::apply_restitution(s.rows, s.cold_rows, ids, s.blocks, s.bodies, settings);
          return 0.0;
        },
        false);
  }
};

// advance_with's parts for one island on one thread (any island: exact, soft, pgs), or, for an
// island of several joint components (`team`), on the whole team: every thread calls every
// member; each solves its share of the components' joints (components share no moving body, and
// each joint's arithmetic is its own, so any split gives the same bits), and thread 0 the
// contacts, which Gauss-Seidel visits in order, between barriers.
class SerialIsland {
 public:
  static constexpr bool kSolvesExact = true;
  SerialIsland(const IslandContext& c, IslandReport* report, bool team = false)
      : c_(c),
        report_(report),
        rows_(c.scratch.rows),
        cold_(c.scratch.cold_rows),
        bodies_(c.scratch.bodies),
        team_(team),
        thread_(team ? omp_get_thread_num() : 0) {
    if (!team_ || thread_ == 0) set_up_trees();
    if (team_) c_.scratch.barrier.wait();
    if (report_->joint_tree && !c.joints.empty())
      trees_ = std::span(c.scratch.joint_trees).subspan(c.first_component, c.component_count);
    // (The island's trees share the thread's index: the first holds any of their bodies.)
    contacts_through_tree_ =
        !trees_.empty() && std::any_of(c.rows.begin(), c.rows.end(), [&](std::uint32_t id) {
          return trees_[0].holds(c.scratch.rows[id].a) || trees_[0].holds(c.scratch.rows[id].b);
        });
    // Only the trees' own rows: their solve is exact, and a second sweep would find it so (unless
    // one holds stiffness: JointTree::stiffened).
    one_sweep_solves_ = !trees_.empty() && c.rows.empty() &&
                        std::none_of(c.joints.begin(), c.joints.end(), [&](std::uint32_t j) {
                          return has_axial_rows(c.scratch.joint_rows[j].joint);
                        });
    // This thread's components: a run of them with about an equal share of the joints.
    mine_ = {0, c.component_count};
    if (team_) {
      const std::size_t threads = static_cast<std::size_t>(omp_get_num_threads());
      const auto first_at_share = [&](std::size_t t) {
        const std::size_t share = c.joints.size() * t / threads;
        std::uint32_t k = 0;
        while (k < c.component_count && component_end(k) <= share)
          ++k;
        return t == threads ? c.component_count : k;
      };
      mine_ = {first_at_share(static_cast<std::size_t>(thread_)),
               first_at_share(static_cast<std::size_t>(thread_) + 1)};
    }
  }

  ~SerialIsland() {
    std::uint32_t take_limit_hits = 0;
    for (std::uint32_t component = mine_.first; component < mine_.second && !trees_.empty();
         ++component)
      take_limit_hits += trees_[component].take_limit_hits();
    if (take_limit_hits > 0) {
#pragma omp atomic
      report_->joint_take_limit_hits += take_limit_hits;
    }
    if (team_) c_.scratch.barrier.wait();  // every thread is done with the trees
    if (team_ && thread_ != 0) return;
    for (JointTree& tree : trees_)
      tree.detach();
  }
  SerialIsland(const SerialIsland&) = delete;
  SerialIsland& operator=(const SerialIsland&) = delete;

  bool has_rows() const { return !c_.rows.empty() || !c_.joints.empty(); }
  void pass_impacts(double reach) {
    if (lead() && tumble::pass_impacts(rows_, cold_, c_.rows, c_.scratch.blocks, bodies_,
                                       c_.settings.solver, reach))
      ++report_->impact_limit_hits;
    if (team_) c_.scratch.barrier.wait();
  }
  void integrate_velocities(double h) {
    const std::uint32_t hits = team_integrate_velocities(c_, h, !team_);
    if (hits == 0) return;
#pragma omp atomic
    report_->gyroscopic_limit_hits += hits;
  }
  // Each move is followed by the joints' position passes (joint_solver.h).
  void integrate_positions(double h) {
    moved_for_ += h;
    team_integrate_positions(c_, h, !team_);
    // Kinematic bodies the joints hold (each joint's own: World::prepare_joint_rows) go where
    // their velocities take them by now, exactly. (An island on the team holds none.)
    if (c_.scratch.kinematic_contacts) {
      for (std::uint32_t j : c_.joints) {
        const JointRow& row = c_.scratch.joint_rows[j];
        for (const std::uint32_t k : {row.a, row.b})
          if (k != kWorldAnchor && bodies_[k].kinematic)
            c_.scratch.poses[k] =
                moved_by(c_.body_of[k]->pose(), bodies_[k].v, bodies_[k].w, moved_for_);
      }
    }
    for (std::uint32_t component = mine_.first; component < mine_.second; ++component) {
      double corrected = std::numeric_limits<double>::infinity();
      // (Where contacts act through the trees, one chord pass more: kLaterBoundSlack.) Joint by
      // joint, the settings' count.
      const int passes = trees_.empty() ? c_.settings.solver.joint_position_passes
                                        : kJointPositionPasses + (contacts_through_tree_ ? 1 : 0);
      for (int pass = 0; pass < passes; ++pass) {
        if (!trees_.empty()) {
          // A pass after the refactored ones corrects what the last left, about the square of
          // what that one corrected: nothing where that was already below kSettledJointError.
          if (pass >= kJointRefactoredPasses && corrected < kSettledJointError) break;
          const bool later_newton =
              pass == kJointRefactoredPasses && contacts_through_tree_ && corrected > kNewtonAfter;
          JointTree& tree = trees_[component];
          const bool first_shares = !contacts_through_tree_ && !tree.stiffened();
          // (Pending after the first pass only where it was given the substep: first_shares.)
          const bool chord_second =
              pass == 1 && corrected < kNewtonAfter && tree.velocity_factors_pending();
          const bool newton = (pass < kJointRefactoredPasses && !chord_second) || later_newton;
          const bool later_bounds = pass == 1 && contacts_through_tree_;
          // The last refactored pass (and a later Newton one) factors the velocity sweeps'
          // system too (joint_tree.h).
          const bool for_sweeps =
              pass == kJointRefactoredPasses - 1 || later_newton || (pass == 0 && first_shares);
          corrected = tree.solve_positions(c_.scratch.joint_rows, bodies_, c_.scratch.poses, newton,
                                           for_sweeps ? h : 0.0, pass == 0 || later_bounds,
                                           later_bounds ? kLaterBoundSlack : 0.0);
          continue;
        }
        for (std::uint32_t j : joints_of(component))
          correct_joint_position(c_.scratch.joint_rows[j], bodies_, c_.scratch.poses);
      }
    }
    // The joints' terms at the poses the passes left: the settling reads their anchors, and the
    // next sweep (nothing moves before it) takes them as they are.
    joint_terms_current_ = false;
    bool settling = false;
    for (std::uint32_t component = mine_.first; component < mine_.second && !trees_.empty();
         ++component)
      settling = settling || trees_[component].velocity_factors_pending();
    if (settling) {
      prepare_joint_terms();
      for (std::uint32_t component = mine_.first; component < mine_.second; ++component)
        trees_[component].settle_velocity_factors(c_.scratch.joint_rows, bodies_, c_.scratch.poses,
                                                  h, !report_->exact_joints,
                                                  c_.scratch.joint_terms);
    }
    if (team_) c_.scratch.barrier.wait();
  }
  void refresh_separations() {
    if (lead() && coloured_contacts()) {
      coloured().refresh_separations(kinematic_time());
    } else if (lead()) {
      update_separations(rows_, c_.rows, bodies_, kinematic_time());
    }
    if (team_) c_.scratch.barrier.wait();
  }
  // How long the island's bodies have moved in this step, which kinematic bodies' motion in its
  // separations follows (0 where none touches a contact: the separations' arithmetic without it).
  double kinematic_time() const { return c_.scratch.kinematic_contacts ? moved_for_ : 0.0; }
  void warm_start(bool keep_last_substep) {
    prepare_joint_terms();
    for (std::uint32_t component = mine_.first; component < mine_.second; ++component) {
      for (std::uint32_t j : joints_of(component)) {
        JointRow& row = c_.scratch.joint_rows[j];
        // With the direct solve, motors join it each substep until one needs more than its force
        // (joint_tree.cc), starting from nothing: the solve finds the whole impulse, and a warm
        // start's push only made a motor swing between its bounds once it met them.
        if (!trees_.empty() && row.joint.motor.enabled) {
          if (!row.motor_in_tree) trees_[component].forget_velocity_factors();  // its row is back
          row.motor_in_tree = true;
          row.motor_at_bound = false;
          row.joint.motor_impulse = 0;
        }
        warm_start_joint(row, bodies_, c_.scratch.poses, c_.scratch.joint_terms[j]);
      }
    }
    if (team_) c_.scratch.barrier.wait();
    if (lead() && coloured_contacts()) {
      coloured().warm_start(keep_last_substep, kinematic_time());
    } else if (lead()) {
      tumble::warm_start(rows_, cold_, c_.rows, bodies_, keep_last_substep, kinematic_time());
    }
    if (team_) c_.scratch.barrier.wait();
  }
  // Joints first, then contacts (Box2D v3's order: the contacts have the last word on
  // penetration).
  double sweep(const Softness* soft, double h, bool backward) {
    if (lead()) ++report_->velocity_iterations;
    double change = 0;
    if (!c_.joints.empty()) {
      // Before a move: the soft solver's sweeps with bias, and every pgs sweep (its move follows).
      const bool move_ahead = soft != nullptr || report_->solver == IslandSolver::kPgs;
      const JointTarget target{move_ahead ? h : 0.0, c_.settings.solver.max_push_velocity, h,
                               one_sweep_solves_};
      // With trees (joint_tree.h), every joint's own rows at once, exactly, after the drives.
      const bool direct = !trees_.empty();
      prepare_joint_terms();
      for (std::uint32_t component = mine_.first; component < mine_.second; ++component) {
        const JointTarget visit = direct ? target : gauss_seidel_target(target, component);
        for (std::uint32_t j : joints_of(component)) {
          JointRow& row = c_.scratch.joint_rows[j];
          const JointPoseTerms& terms = c_.scratch.joint_terms[j];
          row.joint.impulse_time = h;
          // (A joint without drives or bounds has nothing to visit besides the direct solve.)
          if (direct && !has_axial_rows(row.joint)) continue;
          change = std::max(
              change, direct ? solve_joint_drives(row, bodies_, c_.scratch.poses, target, terms)
                             : solve_joint(row, bodies_, c_.scratch.poses, visit, terms));
        }
        if (direct)
          change = std::max(change, trees_[component].solve_velocities(
                                        c_.scratch.joint_rows, bodies_, c_.scratch.poses,
                                        tree_target(target), c_.scratch.joint_terms));
      }
    }
    // Each thread's trees' stiffness goes with its change: past the barrier another may already
    // refactor its own.
    bool stiff = false;
    for (std::uint32_t component = mine_.first; component < mine_.second && !trees_.empty();
         ++component)
      stiff = stiff || trees_[component].stiffened();
    const auto [largest, any_stiff] = team_largest(change, stiff);
    change = largest;
    if (one_sweep_solves_ && !any_stiff) return 0;
    if (c_.rows.empty()) return change;
    double contacts = 0;
    if (lead() && coloured_contacts()) {
      contacts = coloured().sweep(c_.settings.solver, soft, h, backward);
    } else if (lead()) {
      contacts = solve_contacts(rows_, c_.rows, c_.scratch.blocks, bodies_, c_.settings.solver,
                                soft, h, backward);
    }
    return std::max(change, team_largest(contacts, false).first);
  }
  // One substep of an exact island with joints (exact_joints.h): the drives swept and the tree
  // solved as a sweep does them, then the contacts, limits and cones as one LCP. True when its
  // answer was taken; false leaves the drives' and tree's velocities, the contacts' impulses at 0,
  // for the substep's sweeps. (Such an island is one component, never the team's.)
  bool exact_substep(double h, bool keep_last_substep) {
    TUMBLE_ASSERT(trees_.size() == 1 && !team_);
    JointTree& tree = trees_[0];
    // No warm start: the LCP finds each substep's whole impulse (kept for the step's total, as
    // the warm start keeps it).
    update_separations(rows_, c_.rows, bodies_, kinematic_time());
    for (std::uint32_t id : c_.rows) {
      ContactRow& row = rows_[id];
      if (keep_last_substep) cold_[id].earlier_substeps_impulse += row.normal_impulse;
      row.normal_impulse = row.tangent_impulse1 = row.tangent_impulse2 = 0;
    }
    // The LCP finds its rows' whole impulses (the limits' and cones'), and the tree its own from
    // any start; the drives (springs, friction, a locked limit) are warm-started, as in the
    // sweeps: Gauss-Seidel rows beside the tree converge over the substeps only from where the
    // bodies were held (from nothing, a bar's friction on its hinge stopped its turn about its
    // centre, the tree turned its fall back into a turn about the hinge, and it slid at a steady
    // 0.06 rad/s), so a joint with drives keeps its own rows' warm start too. (Warm-started
    // everywhere, a chain of 20 falling from level opened 5e-5 m at dt 1/30; 2.4e-7 m without.)
    prepare_joint_terms();
    for (std::uint32_t j : c_.joints) {
      JointRow& row = c_.scratch.joint_rows[j];
      Joint& joint = row.joint;
      if (!has_axial_rows(joint)) {
        joint.linear_impulse.setZero();
        joint.angular_impulse.setZero();
        joint.axial_impulse = 0;
      }
      joint.swing_impulse = 0;
      if (joint.limit.enabled && joint.limit.lower < joint.limit.upper) joint.limit_impulse = 0;
      joint.impulse_time = h;
      if (joint.motor.enabled) {
        if (!row.motor_in_tree) tree.forget_velocity_factors();
        row.motor_in_tree = true;
        row.motor_at_bound = false;
        joint.motor_impulse = 0;
      }
      warm_start_joint(row, bodies_, c_.scratch.poses, c_.scratch.joint_terms[j]);
    }
    // As many visits as a substep's sweeps and relaxation sweeps give them.
    const JointTarget target{h, c_.settings.solver.max_push_velocity, h, one_sweep_solves_};
    const int visits = c_.settings.solver.soft_iterations + c_.settings.solver.relax_iterations;
    for (int i = 0; i < visits; ++i) {
      ++report_->velocity_iterations;
      double change = 0;
      for (std::uint32_t j : c_.joints)
        change =
            std::max(change, solve_joint_drives(c_.scratch.joint_rows[j], bodies_, c_.scratch.poses,
                                                target, c_.scratch.joint_terms[j], false));
      change =
          std::max(change, tree.solve_velocities(c_.scratch.joint_rows, bodies_, c_.scratch.poses,
                                                 tree_target(target), c_.scratch.joint_terms));
      // The first visit's change leaves out the tree's first solve of the substep (its targets'
      // base), so it is never taken as converged.
      if ((one_sweep_solves_ && !tree.stiffened()) ||
          (i > 0 && change <= c_.settings.solver.velocity_tolerance))
        break;
    }
    const ExactSolveResult exact =
        solve_island_exact(rows_, cold_, c_.rows, c_.scratch.joint_rows, c_.joints, tree, bodies_,
                           c_.scratch.poses, c_.settings.solver, h);
    report_->lemke_pivots += exact.lemke.pivots;
    if (!exact.solved()) {
      report_->exact_failed = true;
      return false;
    }
    report_->needs_position_correction |= !exact.pushed_out;
    return true;
  }
  // Whether an exact substep with joints is followed by relaxation sweeps, as a soft one is:
  // where a contact acts on a body of the island's tree. There the LCP's answer holds the joints
  // at rate zero (tree_target) and the move opens them by their turns' curvature, which the
  // position passes close, turning the rows; the velocities the move ends with then push along
  // rows that are no longer the joints' or the contacts', and a chain of 12 swinging into itself
  // gained 341 J in 20 s from 200 (a probe: with every LCP's answer checked against its own
  // matrix, and no LCP raising the kinetic energy). Relaxed, it keeps its energy as auto does
  // (docs/DYNAMICS.md, "Exact with joints"). Islands whose contacts touch no jointed body keep
  // the exact recipe whole.
  bool relaxes_exact_substeps() const {
    return contacts_through_tree_;
  }
  // True when the LCP's answer was taken; false when it was refused (then pgs solves the island).
  bool solve_exact(double dt) {
    const ExactSolveResult exact =
        solve_contacts_exact(rows_, cold_, c_.rows, bodies_, c_.settings.solver, dt);
    report_->lemke_pivots += exact.lemke.pivots;
    if (!exact.solved()) {
      report_->exact_failed = true;
      return false;
    }
    report_->needs_position_correction = !exact.pushed_out;
    return true;
  }
  // The residual at the velocities solved, then `move` (pgs and exact move here, soft moved in its
  // substeps), then restitution.
  template <class Move = void (*)()>
  void finish(
      double h, Move move = [] {}) {
    if (lead() && coloured_contacts()) {
      report_->residual = coloured().store_impulses(h, kinematic_time());
    } else if (lead()) {
      report_->residual = normal_residual(rows_, c_.rows, bodies_, h, kinematic_time());
    }
    if (team_) c_.scratch.barrier.wait();
    move();
    if (lead()) apply_restitution();
  }
  void apply_restitution() {
    if (coloured_contacts()) {
      coloured().apply_restitution(c_.settings.solver);
      return;
    }
    tumble::apply_restitution(rows_, cold_, c_.rows, c_.scratch.blocks, bodies_,
                              c_.settings.solver);
  }

 private:
  // The island's forests, one a component, built and attached to the thread's index (on a team,
  // thread 0's, which every thread's trees then read: their bodies are their own); or none, where
  // the joints go to Gauss-Seidel sweeps.
  void set_up_trees() {
    const IslandContext& c = c_;
    IslandReport* report = report_;
    // The direct solve takes a joint's body that it does not move to be at rest: joints that
    // hold a kinematic body with a velocity are swept as Gauss-Seidel rows instead.
    if (report->joint_tree && c.scratch.kinematic_contacts) {
      for (std::uint32_t j : c.joints) {
        const JointRow& row = c.scratch.joint_rows[j];
        if (bodies_[row.a].kinematic || (row.b != kWorldAnchor && bodies_[row.b].kinematic)) {
          report->joint_tree = false;
          report->exact_joints = false;
        }
      }
    }
    if (!report->joint_tree || c.joints.empty()) return;
    const auto trees =
        std::span(c.scratch.joint_trees).subspan(c.first_component, c.component_count);
    JointTreeIndex& index = c.scratch.joint_tree_index[omp_get_thread_num()];
    for (std::size_t k = 0; k < trees.size(); ++k) {
      trees[k].attach(&index);
      if (trees[k].build(joints_of(static_cast<std::uint32_t>(k)), c.scratch.joint_rows, bodies_,
                         bodies_.size()))
        continue;
      for (std::size_t built = 0; built <= k; ++built)
        trees[built].detach();
      report->joint_tree = false;
      report->joint_loop = true;
      report->exact_joints = false;
      return;
    }
    // Sized here, on one thread: the trees' solves on the team write their bodies' turns.
    if (index.turns.size() < index.node_of_body.size())
      index.turns.resize(index.node_of_body.size());
  }
  // What the trees hold the joints' rows to in a sweep. Where a contact acts on a tree's body, at
  // rate zero, without the curvature targets of a move ahead (JointTree::solve_velocities; the
  // position passes close what the curvature opens over the move, kNewtonAfter): the joints then
  // push along rows whose rates are zero, which does no work, whatever the contacts do. With the
  // targets, chains of 12 to 40 links swinging into themselves gained 69 to 406 J in 20 s (23 to
  // 35% of their energy), and still 56 to 225 J with the targets taken afresh, in every sweep,
  // from the velocities the contacts left; held at zero they gain at most 0.3% (the step's own
  // swing; docs/DYNAMICS.md, "Joints and contacts"). The drives keep the sweep's target (a
  // spring acts before a move).
  // What the Gauss-Seidel sweeps (soft, pgs) hold a component's joints to. The move's curvature
  // (SHAKE's step) keeps energy only as the joints' whole solve: a lone joint with no contact on
  // the island, which its visit solves. Between joints that the sweeps leave unconverged, and
  // from contacts passed on through them, the curvature's rows pumped energy in: chains of 12 to
  // 30 links released level rose 25 to 37% above the lowest energy they had reached over 20 s
  // (soft; pgs alike), and still did with 300 sweeps a substep (a whip gained 70% in a step).
  // At rate zero they gain at most 1.4% (soft) and 7% (pgs, from its unconverged sweeps: 0.3%
  // with 100), and lose what the joints' chord takes (docs/DYNAMICS.md, "Joints in the
  // Gauss-Seidel sweeps").
  JointTarget gauss_seidel_target(JointTarget target, std::uint32_t component) const {
    target.curvature = component_size(component) == 1 && c_.rows.empty();
    return target;
  }
  JointTarget tree_target(JointTarget target) const {
    if (contacts_through_tree_) target.h = 0;
    return target;
  }
  // Whether its contacts are visited colour by colour (IslandContext::first_colour).
  bool coloured_contacts() const {
    return c_.last_colour > c_.first_colour;
  }
  // A coloured island's contacts (IslandContext::first_colour): the lead thread's alone, in the
  // colours' order.
  ColouredContacts coloured() const {
    return {c_.scratch, c_.first_colour, c_.last_colour, true};
  }
  // Whether this thread does the island's serial parts (the contacts, in order).
  bool lead() const {
    return !team_ || thread_ == 0;
  }
  // The island's joints in its components before k's end.
  std::uint32_t component_end(std::uint32_t k) const {
    return c_.scratch.component_begin[c_.first_component + k + 1] -
           c_.scratch.component_begin[c_.first_component];
  }
  std::uint32_t component_size(std::uint32_t k) const {
    return c_.scratch.component_begin[c_.first_component + k + 1] -
           c_.scratch.component_begin[c_.first_component + k];
  }
  std::span<const std::uint32_t> joints_of(std::uint32_t k) const {
    return std::span(c_.scratch.component_joints)
        .subspan(c_.scratch.component_begin[c_.first_component + k], component_size(k));
  }
  // The largest of every thread's `value` and whether any thread's `flag` is set (on one thread,
  // its own), the same on each: the sweeps' stop is every thread's. Two sets of slots, used in
  // turn: a thread may write the next while another still reads these.
  std::pair<double, bool> team_largest(double value, bool flag) {
    if (!team_) return {value, flag};
    const std::size_t threads = static_cast<std::size_t>(omp_get_num_threads());
    std::vector<double>& slots = c_.scratch.team_values;  // 4 a thread (solve_islands)
    const std::size_t first = (reductions_++ % 2) * 2 * threads;
    slots[first + static_cast<std::size_t>(thread_)] = value;
    slots[first + threads + static_cast<std::size_t>(thread_)] = flag ? 1.0 : 0.0;
    c_.scratch.barrier.wait();
    double largest = 0, any = 0;
    for (std::size_t t = 0; t < threads; ++t) {
      largest = std::max(largest, slots[first + t]);
      any = std::max(any, slots[first + threads + t]);
    }
    return {largest, any > 0};
  }

  const IslandContext& c_;
  IslandReport* report_;
  std::span<ContactRow> rows_;
  std::span<ContactRowCold> cold_;
  std::span<SolverBody> bodies_;
  // What the joints' visits read of the poses (joint_terms.h), worked out once after each move:
  // the first visit after one finds them out of date.
  void prepare_joint_terms() {
    if (joint_terms_current_) return;
    for (std::uint32_t component = mine_.first; component < mine_.second; ++component)
      for (std::uint32_t j : joints_of(component))
        tumble::prepare_joint_terms(c_.scratch.joint_rows[j], bodies_, c_.scratch.poses,
                                    trees_.empty(), &c_.scratch.joint_terms[j]);
    joint_terms_current_ = true;
  }

  bool team_ = false;
  int thread_ = 0;
  std::pair<std::uint32_t, std::uint32_t> mine_;  // this thread's components [first, second)
  std::span<JointTree> trees_;  // the components' joints solved directly (joint_tree.h), if so
  bool one_sweep_solves_ = false;
  bool contacts_through_tree_ = false;  // a contact acts on a body of the island's trees
  bool joint_terms_current_ = false;
  std::uint64_t reductions_ = 0;
  double moved_for_ = 0;  // s: the moves so far this step
};

IslandContext island_context(StepScratch& s, const WorldSettings& settings, std::size_t i) {
  return {
      std::span(s.islands.bodies)
          .subspan(s.islands.body_begin[i], s.islands.body_begin[i + 1] - s.islands.body_begin[i]),
      std::span(s.island_rows)
          .subspan(s.island_row_begin[i], s.island_row_begin[i + 1] - s.island_row_begin[i]),
      std::span(s.islands.joints)
          .subspan(s.islands.joint_begin[i],
                   s.islands.joint_begin[i + 1] - s.islands.joint_begin[i]),
      s.first_component[i],
      s.first_component[i + 1] - s.first_component[i],
      s,
      settings,
      s.body_of,
      s.island_colour_begin[i],
      s.island_colour_begin[i + 1]};
}

// advance_with's parts for up to kWideLanes small islands of the same recipe (soft with the
// settings' substeps, or pgs) at once, on one thread. A small island is too small to split over
// lanes; islands share no moving body, so each takes a lane of the packs (contact_packs.h): pack j
// holds every island's j-th manifold, each island visits its own manifolds in its own order and
// stops its sweeps when it alone has converged: the same bits as solving them one after the other.
class IslandLanes {
 public:
  static constexpr bool kSolvesExact = false;
  IslandLanes(StepScratch& s, const WorldSettings& settings, std::span<const std::uint32_t> islands,
              std::span<ContactPack> packs)
      : s_(s),
        settings_(settings),
        count_(islands.size()),
        packs_(packs),
        // A tall pgs island sweeps to the end (advance_with): none of the item stops early.
        tolerance_(s.reports[islands[0]].pgs_iterations > 0 ? 0.0
                                                            : settings.solver.velocity_tolerance) {
    TUMBLE_ASSERT(count_ <= kWideLanes);
    for (std::size_t k = 0; k < count_; ++k) {
      const std::uint32_t i = islands[k];
      contexts_[k].emplace(island_context(s, settings, i));
      lanes_[k].emplace(*contexts_[k], &s.reports[i]);
      reports_[k] = &s.reports[i];
      manifolds_[k] = manifolds_in(s, i);
    }
    for (std::size_t j = 0; j < packs_.size(); ++j) {
      std::uint32_t lanes[kWideLanes];
      for (std::size_t k = 0; k < kWideLanes; ++k) {
        lanes[k] = kNoManifold;
        if (k >= count_ || j >= manifolds_[k]) continue;
        const ManifoldRows m = s.island_manifolds[s.island_manifold_begin[islands[k]] + j];
        lanes[k] = s.rows[m.ids[0]].manifold;
      }
      pack_manifolds(lanes, s.row_begin, s.rows, s.blocks, s.bodies, &packs_[j]);
    }
  }
  IslandLanes(const IslandLanes&) = delete;
  IslandLanes& operator=(const IslandLanes&) = delete;

  bool has_rows() const { return true; }  // only islands with rows are given lanes
  void pass_impacts(double reach) {
    for (std::size_t k = 0; k < count_; ++k)
      lanes_[k]->pass_impacts(reach);
  }
  void integrate_velocities(double h) {
    for (std::size_t k = 0; k < count_; ++k)
      lanes_[k]->integrate_velocities(h);
  }
  // Each run of sweeps follows a warm start or a move: every island sweeps again.
  void integrate_positions(double h) {
    for (std::size_t k = 0; k < count_; ++k) {
      lanes_[k]->integrate_positions(h);
      active_[k] = -1;
    }
  }
  // The packs solve; the rows take their impulses at the end, for the residual and restitution.
  // (The lanes' islands move together: any lane's clock is theirs.)
  void refresh_separations() {
    for (ContactPack& pack : packs_)
      update_separations(pack, s_.bodies, lanes_[0]->kinematic_time());
  }
  void warm_start(bool keep_last_substep) {
    for (ContactPack& pack : packs_)
      tumble::warm_start(pack, s_.bodies, keep_last_substep, lanes_[0]->kinematic_time());
    for (std::size_t k = 0; k < count_; ++k)
      active_[k] = -1;
  }
  // Returns the largest change over the islands still sweeping; an island whose own sweep changed
  // nothing beyond the tolerance stops, as it would alone.
  double sweep(const Softness* soft, double h, bool backward) {
    std::size_t most = 0;
    for (std::size_t k = 0; k < count_; ++k) {
      if (!active_[k]) continue;
      ++reports_[k]->velocity_iterations;
      most = std::max<std::size_t>(most, manifolds_[k]);
    }
    double change[kWideLanes] = {};
    for (std::size_t j = 0; j < most; ++j) {
      double changes[kWideLanes];
      solve_pack(packs_[backward ? most - 1 - j : j], active_, s_.bodies, settings_.solver, soft, h,
                 changes);
      for (std::size_t k = 0; k < count_; ++k)
        change[k] = std::max(change[k], changes[k]);
    }
    double largest = 0;
    for (std::size_t k = 0; k < count_; ++k) {
      if (!active_[k]) continue;
      largest = std::max(largest, change[k]);
      if (change[k] <= tolerance_) active_[k] = 0;
    }
    return largest;
  }
  template <class Move = void (*)()>
  void finish(
      double h, Move move = [] {}) {
    double residual[kWideLanes] = {};
    for (const ContactPack& pack : packs_) {
      store_impulses(pack, s_.rows, s_.cold_rows);
      double lane_residuals[kWideLanes];
      pack_residuals(pack, s_.bodies, h, lane_residuals, lanes_[0]->kinematic_time());
      for (std::size_t k = 0; k < count_; ++k)
        residual[k] = std::max(residual[k], lane_residuals[k]);
    }
    for (std::size_t k = 0; k < count_; ++k)
      reports_[k]->residual = residual[k];
    move();
    for (std::size_t k = 0; k < count_; ++k)
      lanes_[k]->apply_restitution();
  }

 private:
  StepScratch& s_;
  const WorldSettings& settings_;
  std::size_t count_;
  std::span<ContactPack> packs_;
  double tolerance_;  // an island whose sweep changed no more stops sweeping
  std::array<std::optional<IslandContext>, kWideLanes> contexts_;
  std::array<std::optional<SerialIsland>, kWideLanes> lanes_;
  std::array<IslandReport*, kWideLanes> reports_{};
  std::array<std::uint32_t, kWideLanes> manifolds_{};  // each island's count
  WideMask active_{};                                  // islands still sweeping: their lanes
};

// --- Islands solved by the whole team, colour by colour. Every function below is called by
// every thread of the team (or by one thread outside any team) and contains the worksharing.

std::span<const std::uint32_t> manifold_rows(const StepScratch& s, std::uint32_t manifold) {
  return std::span(s.row_ids).subspan(s.row_begin[manifold],
                                      s.row_begin[manifold + 1] - s.row_begin[manifold]);
}

// The largest of the threads' values, returned to every thread.
double team_max(double local, StepScratch& s) {
  const int threads = omp_get_num_threads();
  if (threads == 1) return local;
  s.team_values[omp_get_thread_num()] = local;
  s.barrier.wait();
  double largest = 0;
  for (int t = 0; t < threads; ++t)
    largest = std::max(largest, s.team_values[t]);
  s.barrier.wait();
  return largest;
}

ManifoldRows manifold_rows_of(const StepScratch& s, std::uint32_t manifold) {
  const std::span<const std::uint32_t> ids = manifold_rows(s, manifold);
  return {ids.data(), static_cast<int>(ids.size())};
}

// Calls pack_fn(pack) for the packs of colours [first, last), forwards or backwards, where
// `packed`, the team splitting each colour's packs, and manifold_fn(manifold rows) for the
// manifolds not packed: the overflow colour's on one thread, in order, and every colour's, split,
// without `packed` (the same order: packs only group a colour's manifolds, which share no moving
// body). Returns the largest value they returned, on every thread (0 without `reduce`, which
// spares the two barriers of the reduction).
template <class PackFn, class ManifoldFn>
double visit_colours(StepScratch& s, std::uint32_t first, std::uint32_t last, bool backward,
                     bool packed, bool solo, PackFn&& pack_fn, ManifoldFn&& manifold_fn,
                     bool reduce) {
  const Colouring& colouring = s.colouring;
  double local = 0;
  for (std::uint32_t k = first; k < last; ++k) {
    const std::uint32_t c = backward ? first + last - 1 - k : k;
    const std::int64_t begin = colouring.colour_begin[c], end = colouring.colour_begin[c + 1];
    if (solo) {
      // One thread, the same order: each colour's manifolds share no moving body, so visiting
      // them in turn gives the bits the team gives.
      if (colouring.serial[c]) {
        for (std::int64_t i = begin; i < end; ++i) {
          const std::int64_t at = backward ? begin + end - 1 - i : i;
          local = std::max(local, manifold_fn(manifold_rows_of(s, colouring.manifolds[at])));
        }
      } else if (!packed) {
        for (std::int64_t i = begin; i < end; ++i)
          local = std::max(local, manifold_fn(manifold_rows_of(s, colouring.manifolds[i])));
      } else {
        for (std::int64_t p = s.colour_pack_begin[c]; p < s.colour_pack_begin[c + 1]; ++p)
          local = std::max(local, pack_fn(s.packs[p]));
      }
      continue;
    }
    // Each colour ends at the team's barrier (team_barrier.h), not OpenMP's.
    if (colouring.serial[c]) {
#pragma omp single nowait
      for (std::int64_t i = begin; i < end; ++i) {
        const std::int64_t at = backward ? begin + end - 1 - i : i;
        local = std::max(local, manifold_fn(manifold_rows_of(s, colouring.manifolds[at])));
      }
    } else if (!packed) {
#pragma omp for schedule(static) nowait
      for (std::int64_t i = begin; i < end; ++i)
        local = std::max(local, manifold_fn(manifold_rows_of(s, colouring.manifolds[i])));
    } else {
      const std::int64_t packs_begin = s.colour_pack_begin[c],
                         packs_end = s.colour_pack_begin[c + 1];
#pragma omp for schedule(static) nowait
      for (std::int64_t p = packs_begin; p < packs_end; ++p)
        local = std::max(local, pack_fn(s.packs[p]));
    }
    s.barrier.wait();
  }
  if (solo) return reduce ? local : 0.0;
  return reduce ? team_max(local, s) : 0.0;
}

// The step's packs where it sweeps them, else the rows.
template <class PackFn, class ManifoldFn>
double sweep_packs(StepScratch& s, std::uint32_t first, std::uint32_t last, bool backward,
                   bool solo, PackFn&& pack_fn, ManifoldFn&& manifold_fn, bool reduce) {
  return visit_colours(s, first, last, backward, s.packed, solo, pack_fn, manifold_fn, reduce);
}

// fn(row ids of a manifold) for every manifold, through the rows.
template <class Fn>
double sweep_colours(StepScratch& s, std::uint32_t first, std::uint32_t last, bool backward,
                     bool solo, Fn&& fn, bool reduce) {
  return visit_colours(
      s, first, last, backward, false, solo, [](const ContactPack&) { return 0.0; },
      [&](const ManifoldRows& m) { return fn(std::span<const std::uint32_t>(m.ids, m.count)); },
      reduce);
}

// Each island's joints in components (StepScratch::component_joints): joints joined through
// bodies that move, numbered by their first joint in the island's order, each its joints in that
// order; an island the exact solver takes with its joints is one. A union-find over the bodies.
void split_joint_components(StepScratch& s) {
  constexpr std::uint32_t kUnnumbered = UINT32_MAX;
  s.first_component.assign(1, 0);
  s.component_begin.assign(1, 0);
  s.component_joints.clear();
  if (s.component_root.size() < s.bodies.size()) {
    s.component_root.resize(s.bodies.size());
    s.component_number.resize(s.bodies.size());
  }
  const auto moving = [&](std::uint32_t k) {
    return k != kWorldAnchor && s.bodies[k].inverse_mass > 0 && !s.bodies[k].kinematic;
  };
  const auto root = [&](std::uint32_t k) {
    while (s.component_root[k] != k) {
      s.component_root[k] = s.component_root[s.component_root[k]];
      k = s.component_root[k];
    }
    return k;
  };
  for (std::size_t i = 0; i + 1 < s.islands.joint_begin.size(); ++i) {
    const auto joints = std::span(s.islands.joints)
                            .subspan(s.islands.joint_begin[i],
                                     s.islands.joint_begin[i + 1] - s.islands.joint_begin[i]);
    std::uint32_t components = 0;
    if (joints.size() == 1 || (!joints.empty() && s.reports[i].exact_joints)) {
      s.component_joints.insert(s.component_joints.end(), joints.begin(), joints.end());
      s.component_begin.push_back(static_cast<std::uint32_t>(s.component_joints.size()));
      components = 1;
    } else if (!joints.empty()) {
      for (std::uint32_t j : joints) {
        for (std::uint32_t k : {s.joint_rows[j].a, s.joint_rows[j].b}) {
          if (!moving(k)) continue;
          s.component_root[k] = k;
          s.component_number[k] = kUnnumbered;
        }
      }
      for (std::uint32_t j : joints) {
        const JointRow& row = s.joint_rows[j];
        if (!moving(row.a) || !moving(row.b)) continue;
        const std::uint32_t x = root(row.a), y = root(row.b);
        s.component_root[std::max(x, y)] = std::min(x, y);
      }
      // Each joint's component (one of its own where neither body moves), then the joints
      // counted into place.
      s.joint_component.clear();
      for (std::uint32_t j : joints) {
        const JointRow& row = s.joint_rows[j];
        const std::uint32_t end = moving(row.a) ? row.a : row.b;
        std::uint32_t component = components;
        if (moving(end)) {
          std::uint32_t& number = s.component_number[root(end)];
          if (number == kUnnumbered) number = components;
          component = number;
        }
        if (component == components) ++components;
        s.joint_component.push_back({component, j});
      }
      const std::size_t first_end = s.component_begin.size();
      const std::uint32_t start = static_cast<std::uint32_t>(s.component_joints.size());
      s.component_begin.resize(first_end + components, 0);
      s.component_cursor.assign(components, 0);
      for (const auto& [component, j] : s.joint_component)
        ++s.component_cursor[component];
      std::uint32_t placed = start;
      for (std::uint32_t c = 0; c < components; ++c) {
        const std::uint32_t count = s.component_cursor[c];
        s.component_cursor[c] = placed;
        placed += count;
        s.component_begin[first_end + c] = placed;
      }
      s.component_joints.resize(placed);
      for (const auto& [component, j] : s.joint_component)
        s.component_joints[s.component_cursor[component]++] = j;
    }
    s.first_component.push_back(s.first_component.back() + components);
  }
  if (s.joint_trees.size() < s.first_component.back())
    s.joint_trees.resize(s.first_component.back());
}

// Whether a coloured island of `manifolds` is solved by the whole team, colour by colour, or by
// one thread beside the other islands (the same bits either way: visit_colours). Each colour ends
// at a barrier, which costs a few microseconds on a team of 16; an island must give each thread
// enough of every colour to pay for it. On 16 cores the landed pile of 4000 (17 coloured islands,
// 4,440 manifolds in all, about 4 colours each) spent its solve at barriers (PERFORMANCE.md,
// "Measured on 16 cores"). Two threads take every coloured island as before.
constexpr std::uint32_t kTeamManifoldsPerThread = 32;
// And an island of several joint components given to the team: its sweeps end at two barriers
// each, and its moves at two.
constexpr std::uint32_t kTeamJointsPerThread = 8;
bool team_runs(int threads, std::uint32_t manifolds) {
  return manifolds >= static_cast<std::uint32_t>(threads) * kTeamManifoldsPerThread;
}

// advance_with's parts for a coloured island (soft or pgs) over the whole team: every member
// is called by every thread of the team and contains the worksharing.
class TeamIsland {
 public:
  static constexpr bool kSolvesExact = false;
  // `solo`: the island is one thread's, inside or outside a team (one too small to be worth the
  // team's barriers at every colour); else every thread of the team calls every member.
  TeamIsland(const IslandContext& c, std::uint32_t first, std::uint32_t last, IslandReport* report,
             bool solo)
      : c_(c), s_(c.scratch), first_(first), last_(last), report_(report), solo_(solo) {}

  bool has_rows() const { return true; }  // coloured islands have many
  // In the rows' order, on one thread: each impact follows from the ones before it. Every thread
  // reads the gate, so that an island where no blow travels (most) costs the team no barrier; the
  // first barrier keeps the pass's writes from the gate's reads.
  void pass_impacts(double reach) {
    if (impact_manifolds(s_.rows, s_.cold_rows, c_.rows, c_.settings.solver) == 0) return;
    if (!solo_) s_.barrier.wait();
    if (solo_ || omp_get_thread_num() == 0) {
      if (tumble::pass_impacts(s_.rows, s_.cold_rows, c_.rows, s_.blocks, s_.bodies,
                               c_.settings.solver, reach))
        ++report_->impact_limit_hits;
    }
    if (!solo_) s_.barrier.wait();
  }
  void integrate_velocities(double h) { hits_ += team_integrate_velocities(c_, h, solo_); }
  void integrate_positions(double h) {
    moved_for_ += h;
    team_integrate_positions(c_, h, solo_);
  }
  double kinematic_time() const { return s_.kinematic_contacts ? moved_for_ : 0.0; }
  // The packs solve; the rows take their impulses at the end, for the residual and restitution.
  void refresh_separations() { contacts().refresh_separations(kinematic_time()); }
  void warm_start(bool keep_last_substep) {
    contacts().warm_start(keep_last_substep, kinematic_time());
  }
  double sweep(const Softness* soft, double h, bool backward) {
    ++iterations_;
    return contacts().sweep(c_.settings.solver, soft, h, backward);
  }
  template <class Move = void (*)()>
  void finish(
      double h, Move move = [] {}) {
    // One pass over the packs for both: a large island's packs come from memory each pass.
    const double residual = contacts().store_impulses(h, kinematic_time());
    move();
    contacts().apply_restitution(c_.settings.solver);
#pragma omp atomic
    report_->gyroscopic_limit_hits += hits_;
    if (solo_ || omp_get_thread_num() == 0) {
      report_->velocity_iterations = iterations_;
      report_->residual = residual;
    }
  }

 private:
  ColouredContacts contacts() const {
    return {s_, first_, last_, solo_};
  }
  const IslandContext& c_;
  StepScratch& s_;
  std::uint32_t first_, last_;
  IslandReport* report_;
  bool solo_;
  std::uint64_t iterations_ = 0;
  std::uint32_t hits_ = 0;
  double moved_for_ = 0;  // s: the moves so far this step
};

}  // namespace

void World::solve_islands(double dt) {
  StepScratch& s = *scratch_;
  const int threads = team_size(settings_.threads);
  // Four a thread: SerialIsland's reductions on a team.
  if (s.team_values.size() < 4 * static_cast<std::size_t>(threads))
    s.team_values.resize(4 * static_cast<std::size_t>(threads));
  split_joint_components(s);
  // Islands of several joint components with enough joints for each thread of the team, largest
  // first (a joint's share of a sweep is about a microsecond; a barrier on a team of 16 a few).
  s.team_joint_islands.clear();
  if (threads > 1 && !s.kinematic_contacts) {
    for (std::uint32_t i : s.single_islands) {
      const std::uint32_t joints = s.islands.joint_begin[i + 1] - s.islands.joint_begin[i];
      if (s.first_component[i + 1] - s.first_component[i] >= 2 && !s.reports[i].exact_joints &&
          joints >= static_cast<std::uint32_t>(threads) * kTeamJointsPerThread)
        s.team_joint_islands.push_back(i);
    }
    std::sort(s.team_joint_islands.begin(), s.team_joint_islands.end(),
              [&](std::uint32_t x, std::uint32_t y) {
                const std::uint32_t jx = s.islands.joint_begin[x + 1] - s.islands.joint_begin[x];
                const std::uint32_t jy = s.islands.joint_begin[y + 1] - s.islands.joint_begin[y];
                return jx != jy ? jx > jy : x < y;
              });
  }
  stats_.team_joint_islands = static_cast<std::uint32_t>(s.team_joint_islands.size());
  // The small islands as work: soft (with the settings' substeps) and pgs islands with rows in
  // groups of kWideLanes (IslandLanes) where the step sweeps packs (tall pgs islands with those
  // of their sweep count), every other one alone (SerialIsland).
  s.work_islands.clear();
  s.work_begin.assign(1, 0);
  auto lane_kind = [&](std::uint32_t i) -> int {
    const IslandReport& report = s.reports[i];
    if (s.island_row_begin[i + 1] == s.island_row_begin[i]) return -1;
    if (!s.packed || report.joints > 0) return -1;
    if (report.solver == IslandSolver::kSoft && report.substeps == 0) return 0;
    if (report.solver == IslandSolver::kPgs) return 1;
    return -1;
  };
  auto manifold_count = [&](std::uint32_t i) { return manifolds_in(s, i); };
  auto coloured = [&](std::uint32_t i) {
    return s.island_colour_begin[i + 1] > s.island_colour_begin[i];
  };
  // Tall pgs islands sweep their own count to the end (tall_stacks.h): only islands with the same
  // count share an item.
  auto sweeps = [&](std::uint32_t i) { return s.reports[i].pgs_iterations; };
  // Coloured islands too small for the team go first, one thread each, largest first.
  s.lane_candidates.clear();
  for (std::uint32_t i : s.team_islands)
    if (!team_runs(threads, manifold_count(i))) s.lane_candidates.push_back(i);
  std::sort(s.lane_candidates.begin(), s.lane_candidates.end(),
            [&](std::uint32_t x, std::uint32_t y) {
              if (manifold_count(x) != manifold_count(y))
                return manifold_count(x) > manifold_count(y);
              return x < y;
            });
  for (std::uint32_t i : s.lane_candidates) {
    s.work_islands.push_back(i);
    s.work_begin.push_back(static_cast<std::uint32_t>(s.work_islands.size()));
  }
  stats_.coloured_islands_alone = static_cast<std::uint32_t>(s.lane_candidates.size());
  for (int kind = 0; kind < 2; ++kind) {
    // Islands of like sizes side by side, largest first: a pack's lanes then run out of
    // manifolds together (four islands of 30, 5, 5 and 2 manifolds would fill 30 packs, 42
    // lanes of 120), and the largest items are handed out first.
    s.lane_candidates.clear();
    for (std::uint32_t i : s.single_islands)
      if (lane_kind(i) == kind) s.lane_candidates.push_back(i);
    std::sort(s.lane_candidates.begin(), s.lane_candidates.end(),
              [&](std::uint32_t x, std::uint32_t y) {
                if (sweeps(x) != sweeps(y)) return sweeps(x) < sweeps(y);
                if (manifold_count(x) != manifold_count(y))
                  return manifold_count(x) > manifold_count(y);
                return x < y;
              });
    for (std::uint32_t i : s.lane_candidates) {
      const std::uint32_t item_size =
          static_cast<std::uint32_t>(s.work_islands.size()) - s.work_begin.back();
      if (item_size == kWideLanes ||
          (item_size > 0 && sweeps(s.work_islands[s.work_begin.back()]) != sweeps(i)))
        s.work_begin.push_back(static_cast<std::uint32_t>(s.work_islands.size()));
      s.work_islands.push_back(i);
    }
    if (s.work_islands.size() > s.work_begin.back())
      s.work_begin.push_back(static_cast<std::uint32_t>(s.work_islands.size()));
  }
  for (std::uint32_t i : s.single_islands) {
    if (lane_kind(i) >= 0 || std::find(s.team_joint_islands.begin(), s.team_joint_islands.end(),
                                       i) != s.team_joint_islands.end())
      continue;
    s.work_islands.push_back(i);
    s.work_begin.push_back(static_cast<std::uint32_t>(s.work_islands.size()));
  }
  const std::int64_t work = static_cast<std::int64_t>(s.work_begin.size()) - 1;
  // Room for the packs of islands solved together, which each item fills itself.
  s.lane_pack_begin.assign(1, 0);
  for (std::int64_t k = 0; k < work; ++k) {
    std::uint32_t most = 0;
    if (s.work_begin[k + 1] - s.work_begin[k] > 1) {
      for (std::uint32_t w = s.work_begin[k]; w < s.work_begin[k + 1]; ++w) {
        most = std::max(most, manifold_count(s.work_islands[w]));
        stats_.packed_manifolds += manifold_count(s.work_islands[w]);
      }
    }
    s.lane_pack_begin.push_back(s.lane_pack_begin.back() + most);
  }
  resize_for_overwrite(s.lane_packs, s.lane_pack_begin.back());
  for (const StepScratch::PackedManifolds& pack : s.pack_manifolds)
    stats_.packed_manifolds += pack.count;
  const bool parallel =
      threads > 1 && (work > 1 || !s.team_islands.empty() || !s.team_joint_islands.empty());
  if (s.joint_tree_index.size() < static_cast<std::size_t>(threads))
    s.joint_tree_index.resize(threads);
  // Large islands one after the other with the whole team, then the rest one island per thread:
  // islands share no body and no row, and colours share no moving body, so any thread count gives
  // the same bits.
  run_region(threads, parallel, [&] {
#pragma omp single
    s.barrier.reset(omp_get_num_threads());
    for (std::uint32_t i : s.team_islands) {
      if (!team_runs(threads, manifold_count(i))) continue;
      const IslandContext context = island_context(s, settings_, i);
      TeamIsland team(context, s.island_colour_begin[i], s.island_colour_begin[i + 1],
                      &s.reports[i], false);
      advance_with(team, &s.reports[i], settings_.solver, dt);
    }
    for (std::uint32_t i : s.team_joint_islands) {
      const IslandContext context = island_context(s, settings_, i);
      SerialIsland island(context, &s.reports[i], true);
      advance_with(island, &s.reports[i], settings_.solver, dt);
    }
    team_for_dynamic(work, [&](std::int64_t k) {
      const std::span<const std::uint32_t> islands =
          std::span(s.work_islands).subspan(s.work_begin[k], s.work_begin[k + 1] - s.work_begin[k]);
      if (islands.size() == 1 && coloured(islands[0]) && s.reports[islands[0]].joints == 0) {
        const IslandContext context = island_context(s, settings_, islands[0]);
        TeamIsland alone(context, s.island_colour_begin[islands[0]],
                         s.island_colour_begin[islands[0] + 1], &s.reports[islands[0]], true);
        advance_with(alone, &s.reports[islands[0]], settings_.solver, dt);
      } else if (islands.size() == 1) {
        const IslandContext context = island_context(s, settings_, islands[0]);
        SerialIsland island(context, &s.reports[islands[0]]);
        advance_with(island, &s.reports[islands[0]], settings_.solver, dt);
      } else {
        IslandLanes lanes(
            s, settings_, islands,
            std::span(s.lane_packs)
                .subspan(s.lane_pack_begin[k], s.lane_pack_begin[k + 1] - s.lane_pack_begin[k]));
        advance_with(lanes, &s.reports[islands[0]], settings_.solver, dt);
      }
    });
  });
  store_joint_impulses();
  for (const IslandReport& report : s.reports) {
    if (report.solver == IslandSolver::kExact || report.exact_joints)
      ++stats_.exact_islands;
    else
      ++stats_.iterative_islands;
    stats_.exact_fallbacks += report.exact_failed ? 1 : 0;
    stats_.exact_oversized += report.exact_oversized ? 1 : 0;
    stats_.joint_tree_islands += report.joint_tree ? 1 : 0;
    stats_.joint_loop_islands += report.joint_loop ? 1 : 0;
    stats_.stiffened_islands += report.substeps > 0 || report.pgs_iterations > 0 ? 1 : 0;
    stats_.stiffness_capped += report.stiffness_capped ? 1 : 0;
    stats_.lemke_pivots += report.lemke_pivots;
    stats_.velocity_iterations += report.velocity_iterations;
    stats_.gyroscopic_limit_hits += report.gyroscopic_limit_hits;
    stats_.joint_take_limit_hits += report.joint_take_limit_hits;
    stats_.impact_limit_hits += report.impact_limit_hits;
    stats_.residual = std::max(stats_.residual, report.residual);
  }
}

void World::correct_positions(double dt) {
  StepScratch& s = *scratch_;
  const SolverSettings& solver = settings_.solver;
  // The moving bodies are where the solve left them; kinematic ones are where their velocities
  // take them (bodies_ keep their start until finish_step).
  if (s.kinematic_contacts)
    for (std::uint32_t k = s.moving; k < s.solver_slot.size(); ++k)
      if (s.bodies[k].kinematic) s.poses[k] = moved_by(s.poses[k], s.bodies[k].v, s.bodies[k].w, dt);
  // Soft islands corrected their penetration inside the substeps, exact ones by their push-out
  // LCP unless it failed.
  auto needs_correction = [&](std::uint32_t i) {
    const IslandReport& report = s.reports[i];
    return report.solver == IslandSolver::kPgs ||
           (report.solver == IslandSolver::kExact &&
            (report.exact_failed || report.needs_position_correction));
  };
  bool any = false;
  for (std::uint32_t i = 0; i < s.reports.size(); ++i)
    any |= needs_correction(i);
  if (!any || solver.position_iterations == 0) return;
  const int threads = team_size(settings_.threads);
  const std::int64_t singles = static_cast<std::int64_t>(s.single_islands.size());
  const std::int64_t coloured = static_cast<std::int64_t>(s.team_islands.size());
  run_region(threads, true, [&] {
#pragma omp single
    s.barrier.reset(omp_get_num_threads());
    auto correct_coloured = [&](std::uint32_t i, bool solo) {
      for (int k = 0; k < solver.position_iterations; ++k) {
        const bool backward = k % 2 == 1;
        sweep_colours(
            s, s.island_colour_begin[i], s.island_colour_begin[i + 1], backward, solo,
            [&](std::span<const std::uint32_t> ids) {
              tumble::correct_positions(s.rows, s.cold_rows, ids, s.bodies, s.poses, solver,
                                        backward);
              return 0.0;
            },
            false);
      }
    };
    for (std::uint32_t i : s.team_islands)
      if (needs_correction(i) && team_runs(threads, manifolds_in(s, i))) correct_coloured(i, false);
    team_for_dynamic(coloured, [&](std::int64_t k) {
      const std::uint32_t i = s.team_islands[k];
      if (needs_correction(i) && !team_runs(threads, manifolds_in(s, i))) correct_coloured(i, true);
    });
    team_for_dynamic(singles, [&](std::int64_t k) {
      const std::uint32_t i = s.single_islands[k];
      if (!needs_correction(i)) return;
      const auto rows = island_context(s, settings_, i).rows;
      for (int n = 0; n < solver.position_iterations; ++n)
        tumble::correct_positions(s.rows, s.cold_rows, rows, s.bodies, s.poses, solver,
                                  n % 2 == 1);
    });
  });
}

std::uint32_t World::wake_touched() {
  std::uint32_t woken = 0;
  for (const Contact& contact : contacts_) {
    const Body& a = bodies_[contact.a.index].body;
    const Body& b = bodies_[contact.b.index].body;
    if (a.asleep && (b.is_moving() || b.carries())) woken += wake_island(a.sleep_island);
    if (b.asleep && (a.is_moving() || a.carries())) woken += wake_island(b.sleep_island);
  }
  return woken;
}

void World::update_sleep(double dt) {
  StepScratch& s = *scratch_;
  const SolverSettings& solver = settings_.solver;
  drop_woken_contacts();  // before islands fall asleep, perhaps under the ids of woken ones
  // Room for every contact of this step to come to rest, reserved ahead (doubling): a resting
  // scene moves its manifolds from contacts_ to here, and the step allocates nothing for it.
  const auto reserve = [](auto& store, std::size_t room) {
    if (store.capacity() < room) store.reserve(std::max(room, 2 * store.capacity()));
  };
  reserve(resting_contacts_, resting_contacts_.size() + contacts_.size());
  reserve(resting_island_, resting_island_.size() + contacts_.size());
  reserve(resting_forces_, resting_forces_.size() + impulses_.size());
  // Bodies a moving kinematic body touches stay awake, however slowly it moves them.
  s.carried.assign(s.kinematic_contacts ? s.solver_slot.size() : 0, 0);
  if (s.kinematic_contacts) {
    for (const Contact& contact : contacts_) {
      const std::uint32_t a = s.solver_of_slot[contact.a.index];
      const std::uint32_t b = s.solver_of_slot[contact.b.index];
      if (s.bodies[a].kinematic) s.carried[b] = 1;
      if (s.bodies[b].kinematic) s.carried[a] = 1;
    }
    for (const JointRow& row : s.joint_rows) {
      if (row.b == kWorldAnchor) continue;
      if (s.bodies[row.a].kinematic) s.carried[row.b] = 1;
      if (s.bodies[row.b].kinematic) s.carried[row.a] = 1;
    }
  }
  // A body is quiet while it is slower than the sleep speeds or stays within the distance and the
  // turn those speeds cover in the sleep delay of its sleep anchor (where it was when that test
  // last began): a box that rocks or jitters in place on uneven ground, faster than the speeds at
  // the peaks, counts as quiet too, as it does in Jolt (Body::UpdateSleepStateInternal keeps its
  // bodies' points inside spheres over the delay), and a body creeping slower than the speeds
  // counts as before.
  const double window = std::max(solver.sleep_delay, dt);
  const double reach = solver.sleep_linear_speed * window;
  const double turn = solver.sleep_angular_speed * window;
  // Each body's timer over the team (each its own), then each island's shortest.
  const std::int64_t island_bodies = static_cast<std::int64_t>(s.islands.bodies.size());
  for_indices(
      team_size(settings_.threads), worth_a_team(island_bodies, 34), island_bodies,
      [&](std::int64_t k) {
        Body& body = bodies_[s.solver_slot[s.islands.bodies[k]]].body;
        const auto anchor_here = [&body] {
          body.sleep_anchor_position = body.position;
          body.sleep_anchor_orientation = body.orientation;
        };
        if (body.sleep_timer == 0) anchor_here();
        const bool slow = body.linear_velocity.norm() < solver.sleep_linear_speed &&
                          body.angular_velocity.norm() < solver.sleep_angular_speed;
        const bool near = (body.position - body.sleep_anchor_position).norm() <= reach &&
                          angle_between(body.sleep_anchor_orientation, body.orientation) <= turn;
        const bool carried = !s.carried.empty() && s.carried[s.islands.bodies[k]];
        body.sleep_timer = (slow || near) && !carried ? body.sleep_timer + dt : 0.0;
        if (!near) anchor_here();
      });
  bool fell_asleep = false;
  for (std::size_t i = 0; i < s.islands.count(); ++i) {
    if (!solver.sleeping) break;
    double shortest = std::numeric_limits<double>::infinity();
    for (std::uint32_t k = s.islands.body_begin[i]; k < s.islands.body_begin[i + 1]; ++k)
      shortest = std::min(shortest, bodies_[s.solver_slot[s.islands.bodies[k]]].body.sleep_timer);
    if (shortest < solver.sleep_delay) continue;
    // Named by its lowest slot (solver indices keep the slots' order).
    const std::uint32_t island = s.solver_slot[s.islands.bodies[s.islands.body_begin[i]]];
    keep_resting_contacts(island, static_cast<std::uint32_t>(i), dt);
    for (std::uint32_t k = s.islands.body_begin[i]; k < s.islands.body_begin[i + 1]; ++k) {
      const std::uint32_t slot = s.solver_slot[s.islands.bodies[k]];
      Body& body = bodies_[slot].body;
      body.asleep = true;
      body.sleep_island = island;
      link_sleeper(slot, island);
      resting_changed(slot);
      if (sleepers_indexed_) recent_sleepers_.push_back(slot);
      body.linear_velocity.setZero();
      body.angular_velocity.setZero();
      note_event(slot, kBodyFellAsleep);
      fell_asleep = true;
    }
  }
  if (fell_asleep) {
    awake_stale_ = true;  // the sleepers leave the moving set
  }
  stats_.sleeping_bodies = static_cast<std::uint32_t>(sleeping_count_);
  stats_.resting_contact_points = static_cast<std::uint32_t>(resting_forces_.size());
}

void World::finish_step(double dt) {
  StepScratch& s = *scratch_;
  const int threads = team_size(settings_.threads);
  const std::int64_t moving = s.moving;
  const std::int64_t manifolds = static_cast<std::int64_t>(contacts_.size());
  TUMBLE_ASSERT(s.cold_rows.size() == s.rows.size() && s.row_begin.size() == contacts_.size() + 1 &&
                s.row_begin.back() == s.rows.size());
  TUMBLE_ASSERT(s.next_pairs.size() == contacts_.size());
  impulses_.resize(s.rows.size());
  std::uint32_t non_finite = 0, slowed = 0, stopped = 0;
  run_region(threads, worth_a_team(moving + manifolds, 33), [&] {
    std::uint32_t my_non_finite = 0, my_slowed = 0, my_stopped = 0;
#pragma omp for schedule(static) nowait
    for (std::int64_t k = 0; k < moving; ++k) {
      Body& body = bodies_[s.solver_slot[k]].body;
      const std::uint8_t guard =
          take_step_result(&body, s.poses[k], s.bodies[k].v, s.bodies[k].w, settings_.limits);
      my_non_finite += (guard & kStepNonFinite) != 0;
      my_slowed += (guard & kStepSlowed) != 0;
      my_stopped += (guard & kStepAtEdge) != 0;
    }
#pragma omp atomic update
    non_finite += my_non_finite;
#pragma omp atomic update
    slowed += my_slowed;
#pragma omp atomic update
    stopped += my_stopped;
#pragma omp for schedule(static)
    for (std::int64_t m = 0; m < manifolds; ++m) {
      for (std::uint32_t r = s.row_begin[m]; r < s.row_begin[m + 1]; ++r) {
        const ContactRow& row = s.rows[r];
        // The impulses stay with the pair's record for the next step's warm start.
        ContactPointRecord& point = s.next_pairs[m].points[row.block_index];
        point.normal_impulse = row.normal_impulse;
        point.friction_impulse =
            row.tangent_impulse1 * row.tangent1 + row.tangent_impulse2 * row.tangent2;
        impulses_[r] = s.cold_rows[r].earlier_substeps_impulse + row.normal_impulse;
      }
    }
  });
  // Every body the step integrated moved (listed after the parallel loop: the list is ordered).
  for (std::int64_t k = 0; k < moving; ++k)
    note_event(s.solver_slot[k], kBodyMoved);
  stats_.non_finite_bodies = non_finite;
  stats_.slowed_bodies = slowed;
  stats_.bodies_at_edge = stopped;
  std::swap(s.pairs, s.next_pairs);
  if (!kinematic_.empty()) move_kinematic(dt);
  time_ += dt;
}

void World::move_kinematic(double dt) {
  for (std::uint32_t slot : kinematic_) {
    Body& body = bodies_[slot].body;
    if (!body.carries()) continue;
    const std::uint8_t guard =
        take_step_result(&body, moved_by(body.pose(), body.linear_velocity,
                                         body.angular_velocity, dt),
                         body.linear_velocity, body.angular_velocity, settings_.limits);
    stats_.bodies_at_edge += (guard & kStepAtEdge) != 0;
    note_event(slot, kBodyMoved);
    // Stopped at the world's edge: it rests from now on, as a static body does.
    if (!body.carries()) resting_changed(slot);
  }
}

}  // namespace tumble

namespace tumble {

std::string_view solver_name(SolverKind kind) {
  switch (kind) {
    case SolverKind::kExact:
      return "exact";
    case SolverKind::kPgs:
      return "pgs";
    case SolverKind::kSoft:
      return "soft";
    case SolverKind::kAuto:
      return "auto";
  }
  return "auto";
}

std::optional<SolverKind> solver_from_name(std::string_view name) {
  for (SolverKind kind :
       {SolverKind::kExact, SolverKind::kPgs, SolverKind::kSoft, SolverKind::kAuto})
    if (solver_name(kind) == name) return kind;
  return std::nullopt;
}

}  // namespace tumble
