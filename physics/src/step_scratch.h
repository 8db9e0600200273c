// The step's working memory, kept by the world and reused from step to step.
#pragma once

#include <vector>

#include "broad_phase.h"
#include "colouring.h"
#include "contact_packs.h"
#include "contact_pairs.h"
#include "contact_solver.h"
#include "continuous.h"
#include "islands.h"
#include "joint_solver.h"
#include "joint_terms.h"
#include "joint_tree.h"
#include "scratch_buffer.h"
#include "tall_stacks.h"
#include "team_barrier.h"

namespace tumble {

enum class IslandSolver : std::uint8_t { kExact, kPgs, kSoft };

struct IslandReport {
  IslandSolver solver = IslandSolver::kSoft;
  bool exact_failed = false;
  bool exact_oversized = false;            // asked for exact, too large: solved soft
  bool needs_position_correction = false;  // exact, but its push-out LCP failed
  std::uint32_t gyroscopic_limit_hits = 0;
  std::uint32_t impact_limit_hits = 0;  // 1 when pass_impacts hit its bound
  std::uint32_t joint_take_limit_hits = 0;  // StepStats::joint_take_limit_hits
  std::uint64_t lemke_pivots = 0, velocity_iterations = 0;
  double residual = 0;
  // Soft islands tall enough to buckle (tall_stacks.h): their substeps and spring; 0 for the
  // settings'.
  int substeps = 0;
  double contact_hertz = 0;
  // Pgs islands tall enough to buckle: all their sweeps, this many (0: the settings').
  int pgs_iterations = 0;
  bool stiffness_capped = false;
  std::uint32_t joints = 0;  // the island's joints: it is solved on one thread, soft or pgs
  // Its joints' rows solved directly (joint_tree.h: exact and auto), or asked to be and found
  // to close a loop (then Gauss-Seidel).
  bool joint_tree = false;
  bool joint_loop = false;
  // Exact with joints (exact_joints.h): each substep's contacts, limits and cones one LCP, the
  // joints held through their tree; the soft recipe's substeps and moves around it.
  bool exact_joints = false;
};

// An island this large is worth splitting over threads (and is split with one thread too, so the
// answer does not depend on the thread count).
constexpr std::uint32_t kColouredIsland = 64;

// A slot without a solver body this step.
constexpr std::uint32_t kNoSolverBody = UINT32_MAX;

struct StepScratch {
  // The world's own (it keeps the cells of the bodies that do not move from step to step).
  HashGrid grid;
  SweepAndPrune sweep;  // likewise its order along x
  // The step's bodies, dense, by solver index: the moving bodies in slot order, then the other
  // bodies this step's contacts touch (statics: inverse mass 0, never written). A step visits
  // these and not every slot of the world. Every per-body array below, the islands, the colouring
  // and the rows' and packs' bodies are by solver index; solver_of_slot numbers a slot
  // (kNoSolverBody where it has none), solver_slot names it back.
  std::vector<std::uint32_t> solver_slot, solver_of_slot;
  std::uint32_t moving = 0;  // solver indices [0, moving) move
  ScratchBuffer<SolverBody> bodies;  // (load_solver_bodies assigns each whole)
  ScratchBuffer<Pose> poses;
  std::vector<std::uint8_t> dynamic;  // 1 for [0, moving)
  // Some contact touches a kinematic body with a velocity (SolverBody::kinematic): the solvers'
  // separations count its motion, and what it touches does not fall asleep (carried, by solver
  // index, made by update_sleep).
  bool kinematic_contacts = false;
  std::vector<std::uint8_t> carried;
  std::vector<const Body*> body_of;
  // (Written whole by prepare_rows each step: ScratchBuffer, scratch_buffer.h.)
  ScratchBuffer<ContactRow> rows;           // manifold order
  ScratchBuffer<ContactRowCold> cold_rows;  // beside rows, row for row
  ScratchBuffer<NormalBlock> blocks;        // one per manifold
  std::vector<std::uint32_t> row_begin;   // rows of manifold m: [row_begin[m], row_begin[m+1])
  std::vector<IslandLink> links;          // one per manifold
  // The joints with a moving body (world_joints.cc), and their links into islands.
  std::vector<JointRow> joint_rows;
  std::vector<IslandLink> joint_links;
  std::vector<JointPoseTerms> joint_terms;  // beside joint_rows: each island's, after its moves
  std::vector<std::uint8_t> touching;  // per manifold: apart by less than the slop
  // Per manifold: its pair's colour last step and this step's (colouring.h).
  std::vector<std::uint8_t> kept_colours, colours;
  Islands islands;
  std::vector<std::uint32_t> island_rows;  // row ids, island by island
  std::vector<std::uint32_t> island_row_begin;
  std::vector<IslandReport> reports;
  std::vector<std::uint32_t> row_ids;  // 0, 1, 2, ...: a manifold's rows as an id span
  // Island i's manifolds: island_manifolds[island_manifold_begin[i] .. [i+1]), spans of
  // island_rows.
  std::vector<ManifoldRows> island_manifolds;
  std::vector<std::uint32_t> island_manifold_begin;
  // The small islands' work: item k is islands work_islands[work_begin[k] .. work_begin[k+1]),
  // several only when they are solved together (IslandLanes).
  std::vector<std::uint32_t> work_islands, work_begin;
  std::vector<std::uint32_t> lane_candidates;  // islands of one recipe, to be grouped
  // Islands solved together sweep packs (contact_packs.h), lane k for the item's k-th island:
  // item k's are lane_packs[lane_pack_begin[k] .. [k+1]), pack j holding each island's j-th
  // manifold.
  ScratchBuffer<ContactPack> lane_packs;  // each filled whole by its item (IslandLanes)
  std::vector<std::uint32_t> lane_pack_begin;
  // Islands with at least kColouredIsland manifolds are solved by the whole team, colour by
  // colour: island i has colours [island_colour_begin[i], island_colour_begin[i+1]).
  Colouring colouring;
  ColouringScratch colouring_scratch;
  std::vector<std::uint32_t> island_colour_begin;
  std::vector<std::uint32_t> team_islands, single_islands;
  // Their parallel colours' manifolds in packs for the sweeps (contact_packs.h): colour c's packs
  // are packs[colour_pack_begin[c] .. [c+1]), none for the overflow colour. Pack k holds the
  // manifolds colouring.manifolds[pack_manifolds[k].first ..][.. count).
  struct PackedManifolds {
    std::uint32_t first = 0, count = 0;
  };
  bool packed = false;  // this step sweeps packs (packed_sweeps())
  // A colour's manifolds while they are grouped by size, one buffer per thread.
  std::vector<std::vector<std::uint32_t>> thread_grouped;
  ScratchBuffer<ContactPack> packs;  // each filled whole by pack_manifolds
  std::vector<PackedManifolds> pack_manifolds;
  std::vector<std::uint32_t> colour_pack_begin;
  std::vector<double> team_values;  // one per thread, for reductions inside a team
  TeamBarrier barrier;              // the solver regions' barrier (team_barrier.h)
  // Continuous collision: pairs with a fast body, their results, and each slot's first impact.
  std::vector<std::uint32_t> swept_pairs;
  std::vector<ImpactResult> impacts;
  std::vector<double> first_impact;
  // Whether a body's first impact stopped it in a contact it touched from the start (its solved
  // velocities stand: the solve already met that contact).
  std::vector<std::uint8_t> impact_in_contact;
  std::vector<std::uint32_t> support_level;               // for tall_stacks.h
  std::vector<std::vector<LevelSums>> thread_level_sums;  // for tall_stacks.h, one per thread
  // An island's joints in components: joints joined through bodies that move (statics, kinematic
  // bodies and the world join nothing: the joints push them not). Components share no moving
  // body, so a team can solve them side by side (SerialIsland). Island i's components are
  // first_component[i] .. first_component[i + 1]; component c's joints (indices into
  // joint_rows, in the island's order) component_joints[component_begin[c] ..
  // component_begin[c + 1]]. An island the exact solver takes with its joints is one component.
  std::vector<std::uint32_t> first_component, component_begin, component_joints;
  // By solver index: the union-find over moving bodies, and each root's component.
  std::vector<std::uint32_t> component_root, component_number;
  std::vector<std::uint32_t> component_cursor;  // by component: where its next joint goes
  std::vector<std::pair<std::uint32_t, std::uint32_t>> joint_component;  // (component, joint)
  // Islands with joints solved by the whole team, component by component (SerialIsland).
  std::vector<std::uint32_t> team_joint_islands;
  // For joint_tree.h: a forest per component (their order among the islands: the islands' order
  // is the same from step to step while nothing joins or parts, so each keeps its forest), and
  // the index a forest looks bodies up in, one per thread (it is as long as the step's bodies).
  std::vector<JointTree> joint_trees;
  std::vector<JointTreeIndex> joint_tree_index;
  // The touching pairs as the last step left them, with their impulses (contact_pairs.h), sorted
  // by body pair; and this step's, contact for contact, with the index of each one's record in
  // `pairs` (kNoRecord: none) and whether its manifold was taken from there.
  // (Each of next_pairs assigned whole before it is read: ScratchBuffer, scratch_buffer.h.)
  ScratchBuffer<ContactPairRecord> pairs, next_pairs;
  static constexpr std::uint8_t kPairTouches = 1, kPairKeptFeature = 2;
  // The narrow phase's output by broad-phase pair, before the touching ones are copied out to the
  // world's contacts and next_pairs. Each pair's contact is written before it is read, and its
  // record where it touches (only those are read), so growing them writes nothing
  // (ScratchBuffer); they are never cut back.
  ScratchBuffer<Contact> found_contacts;
  ScratchBuffer<ContactPairRecord> found_records;
  std::vector<std::uint32_t> found_previous;  // the record of the last step, or kNoRecord
  std::vector<std::uint8_t> found_flags;      // kPairTouches, kPairKeptFeature
  std::vector<std::uint8_t> unjoined;         // 1: a joint keeps the pair apart
  std::vector<std::uint32_t> kept_index;      // where a touching pair goes in `contacts`
  std::vector<double> manifold_depth;         // each manifold's depth, for the step's deepest
  std::vector<std::uint32_t> previous_pair;
  std::vector<std::uint8_t> reused;
  // Pairs with terrain or a compound, which may touch along several manifolds: each such
  // broad-phase pair's place in many_found (kNotMany for the others), which holds where its room
  // starts in the flat arrays below, how many manifolds the pair can have (most_manifolds) and
  // how many it has. Its first manifold goes where any pair's goes, the others after it; their
  // records follow one another in `pairs`, in the same order. The arrays are never cut back.
  struct ManyFound {
    std::uint32_t first = 0, room = 0, count = 0;
  };
  static constexpr std::uint32_t kNotMany = UINT32_MAX;
  std::vector<std::uint32_t> many_slot;
  std::vector<ManyFound> many_found;
  std::vector<ContactManifold> many_manifolds;
  std::vector<ContactPairRecord> many_records;
  std::vector<std::uint32_t> many_previous;
  std::vector<PartFeature> many_features;  // a compound's part pairs' features (narrow_phase.h)
};

}  // namespace tumble
