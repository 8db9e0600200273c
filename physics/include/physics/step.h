// How the world steps: the contact solver and its settings, and what a step reports.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

namespace tumble {

enum class SolverKind : std::uint8_t {
  kExact,  // one linear complementarity problem per island, solved by Lemke's algorithm
  kPgs,    // projected Gauss-Seidel (sequential impulses), warm-started, one velocity solve
  kSoft,   // substeps with soft contacts: solve with bias, integrate, relax without bias
  kAuto,   // exact for islands of several bodies with up to `exact_max_points` contact points
           // where soft would answer otherwise (a mass ratio above 4, a body smaller than 100
           // soft sags); soft for the rest
};
std::string_view solver_name(SolverKind kind);
std::optional<SolverKind> solver_from_name(std::string_view name);

struct SolverSettings {
  SolverKind kind = SolverKind::kAuto;
  // Velocity iterations: per step for pgs, per substep for soft (the relax pass does as many).
  int iterations = 10;
  int soft_iterations = 3;
  int relax_iterations = 3;  // soft: sweeps without bias after each substep's move
  // pgs and soft stop sweeping once a sweep changes no contact velocity by more than this (m/s);
  // resting scenes, warm-started, then need one sweep. 0 always runs every iteration.
  double velocity_tolerance = 1e-4;
  int substeps = 4;  // soft only; the others take one step of dt
  // Position iterations after the velocity solve (pgs, and exact islands that fell back to it):
  // nonlinear Gauss-Seidel that moves bodies out of penetration without adding velocity.
  int position_iterations = 3;
  // Nonlinear Gauss-Seidel passes over the joints after each move, where joints are solved joint
  // by joint (soft and pgs; joint loops under auto; trees under auto take Newton passes instead).
  // Each pass closes part of what the velocity sweeps left open; 0 leaves the joints to the
  // sweeps' drift correction alone. Fewer passes cost less and hold less (docs/PERFORMANCE.md).
  int joint_position_passes = 3;
  // auto: an island with at most this many contact points may go to the exact solver.
  int exact_max_points = 12;
  // Directions of the friction pyramid in the exact solver (its facets); 4 to 32. The first one
  // follows the sliding direction, so a sliding body feels the full Coulomb force.
  int friction_directions = 8;
  // Lemke: pivots allowed per unknown before the island falls back to pgs.
  int lemke_pivots_per_unknown = 20;
  // Exact solver: islands with more contact points than this go to the soft solver instead, so
  // that memory (the LCP is dense: (10 points)^2 doubles with 8 friction directions) and time
  // stay bounded whatever the scene; StepStats::exact_oversized counts them. 1 to 256.
  int exact_max_island_points = 48;
  // Exact solver: the largest velocity error (m/s) an answer may have, measured on the problem
  // without its regularisation; a worse answer is refused and the island falls back to pgs.
  double exact_velocity_tolerance = 5e-3;
  // Islands whose bodies have all been quiet for `sleep_delay` fall asleep and cost nothing until
  // a moving body touches them or a body they rest on is removed. A body is quiet while it is
  // slower than both speeds, or while it stays within the distance and the turn they cover in the
  // delay (2.5 cm and 0.025 rad by default) of where it was: one rocking in place counts too.
  bool sleeping = true;
  double sleep_linear_speed = 0.05;    // m/s
  double sleep_angular_speed = 0.05;   // rad/s
  double sleep_delay = 0.5;            // s
  double slop = 1e-4;                  // m: penetration left alone, so resting contacts keep still
  double speculative_distance = 0.02;  // m: gap below which contacts exist even at rest
  double restitution_threshold = 1.0;  // m/s: slower impacts do not bounce
  // A touching pair of polytopes (boxes, hulls) whose points of contact have moved by no more
  // than this fraction of the smaller body's size since the separating-axis test last searched
  // all its features keeps the feature it found (a face, or a pair of edges) and clips it again
  // at the present poses: resting contacts skip the search, which is most of a box pair's cost.
  // 0 searches every pair every step. At most 0.01.
  double manifold_reuse = 1e-3;
  // Continuous collision: a body that would move more than `continuous_fraction` of its inner
  // radius in a step (for a box, its smallest half extent) keeps speculative contacts only that
  // far and is swept through the rest of its motion after the solve; the first time it comes
  // within half the speculative distance of another body, it stops there for this step, with
  // the velocities it had at that time; the next step's contact decides what happens. Scenes
  // without fast bodies run no sweep at all.
  bool continuous = true;
  double continuous_fraction = 0.75;
  int continuous_iterations = 32;     // conservative-advancement steps per swept pair
  double contact_hertz = 60;          // soft: stiffness of the contact spring, Hz
  double contact_damping_ratio = 10;  // soft: its damping ratio (strongly over-damped)
  double max_push_velocity = 3;       // m/s: penetration is resolved no faster than this
  double max_correction = 0.2;        // m: position correction per iteration (pgs)
  // Fraction of the penetration corrected per position iteration (pgs) or per step (exact).
  double baumgarte = 0.2;
};

// Wall time of the step's stages, seconds.
struct StageTimes {
  double broad_phase = 0, narrow_phase = 0, prepare = 0, solve = 0, correct_positions = 0,
         continuous = 0, total = 0;
};

struct StepStats {
  std::uint64_t step = 0;  // steps taken so far, this one included
  std::uint32_t pairs = 0, manifolds = 0, contact_points = 0;
  std::uint32_t islands = 0, exact_islands = 0, iterative_islands = 0;
  // Large islands split over the team by graph colouring (and large jointed islands, whose
  // contacts are swept colour by colour on one thread): how many, their colours in all, and the
  // manifolds left to the serial overflow colour.
  std::uint32_t coloured_islands = 0, colours = 0, overflow_manifolds = 0;
  // Coloured islands solved by one thread beside the others, colour by colour, the same bits:
  // too small to give each thread of the team 32 manifolds (each colour costs the team a barrier).
  std::uint32_t coloured_islands_alone = 0;
  // Manifolds swept four at a time in SIMD lanes (a colour's, or small islands' side by side).
  std::uint32_t packed_manifolds = 0;
  // Manifolds clipped on the feature a pair kept instead of searching all features again
  // (SolverSettings::manifold_reuse).
  std::uint32_t reused_manifolds = 0;
  // Islands the exact solver could not finish (pivot bound, ray termination, an answer off by
  // more than exact_velocity_tolerance): solved by pgs.
  std::uint32_t exact_fallbacks = 0;
  // Islands the exact solver was asked for but were larger than exact_max_island_points: soft.
  std::uint32_t exact_oversized = 0;
  std::uint64_t lemke_pivots = 0;
  // Islands tall enough to buckle (docs/DYNAMICS.md "Tall stacks"): soft ones given more
  // substeps and a stiffer spring, pgs ones more sweeps and no early stop; and islands that
  // needed more than the bounds (32 substeps, 256 sweeps): they take the bound, or (soft) keep
  // the settings when even 32 substeps would leave them far past it (a light block under a
  // billion times its mass).
  std::uint32_t stiffened_islands = 0, stiffness_capped = 0;
  std::uint64_t velocity_iterations = 0;  // pgs and soft, summed over islands and substeps
  // Largest complementarity residual of a normal contact row after the solve, m/s:
  // |min(impulse / effective mass, normal velocity - target)|; 0 when exactly solved.
  double residual = 0;
  std::uint32_t sleeping_bodies = 0, woken_bodies = 0;
  // Contact points of sleeping islands (World::resting_contacts): they still carry the weight,
  // but the step did not solve them.
  std::uint32_t resting_contact_points = 0;
  // Bodies the step solved: the moving ones and the others their contacts touch (statics).
  // Sleepers and untouched statics cost the solver nothing, however many the world holds.
  std::uint32_t solver_bodies = 0;
  // Continuous collision: bodies swept, of those stopped early, and swept pairs that hit the
  // iteration bound (they stop at the last safe time).
  std::uint32_t swept_bodies = 0, continuous_impacts = 0, continuous_limit_hits = 0;
  double max_penetration = 0;  // m, the deepest contact point found this step
  // Joints the step solved (those with a moving body) and the farthest any was from holding at
  // the solve's end (World::joint_error's measure: m, or rad for axes and rotations). The joint
  // passes are a fixed few a move; this says when they were not enough.
  std::uint32_t solved_joints = 0;
  // Islands whose joints were solved directly (exact and auto, joint_tree.h), and islands that
  // asked for it but whose joints close a loop (solved by Gauss-Seidel sweeps instead).
  std::uint32_t joint_tree_islands = 0;
  std::uint32_t joint_loop_islands = 0;
  // Islands of several joint components (ragdolls in a heap: joints join each ragdoll, contacts
  // join them all) solved by the whole team, each thread its share of the components.
  std::uint32_t team_joint_islands = 0;
  double joint_error = 0;
  std::uint32_t collision_flags = 0;
  // Bodies whose implicit gyroscopic step hit its Newton iteration bound or spun too fast for
  // kGyroscopicMaxPieces; they kept their body-frame spin for the step.
  std::uint32_t gyroscopic_limit_hits = 0;
  // Substeps of islands of joints alone (no contacts, drives or bounds) whose direct solve's
  // curvature targets (SHAKE's iteration, docs/DYNAMICS.md) stopped at their bound of takes or
  // stopped converging before they settled; the position passes corrected what they left.
  std::uint32_t joint_take_limit_hits = 0;
  // 1 when the broad phase found more pairs than World::max_pairs and kept the first ones (bodies
  // heaped inside one another).
  std::uint32_t pair_limit_hits = 0;
  // Islands whose impacts, passed on contact by contact through touching bodies before the solve
  // (Newton's cradle: docs/DYNAMICS.md, "Restitution"), were still travelling at the bound on
  // their sweeps; the contacts still approaching were left to the solve.
  std::uint32_t impact_limit_hits = 0;
  // The world's limits (WorldLimits) held by the step: bodies whose step produced a non-finite
  // value (they keep their pose from before the step, at rest), bodies slowed to the speed
  // limits, and bodies held at the edge of the world (max_coordinate).
  std::uint32_t non_finite_bodies = 0, slowed_bodies = 0, bodies_at_edge = 0;
  StageTimes time;
  // Of each stage's time, the wall time its parallel regions took (the rest ran on the stepping
  // thread alone: serial), and the thread-seconds the team spent waiting at those regions' ends
  // for its slowest thread (imbalance). Zero on one thread. bench_threads reads them.
  StageTimes parallel_time, idle_time;
};

}  // namespace tumble
