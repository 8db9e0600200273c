// Stage "islands": the touching bodies grouped into islands, and for each the solver that
// advances it (exact, pgs or soft, and for auto which) with the substeps or iterations a tall
// stack needs.
#include <omp.h>

#include <algorithm>
#include <span>

#include "auto_solver.h"
#include "colouring.h"
#include "contact_packs.h"
#include "contact_pairs.h"
#include "contact_solver.h"
#include "islands.h"
#include "joint_axial.h"
#include "parallel.h"
#include "physics/world.h"
#include "step_scratch.h"
#include "step_stages.h"
#include "tall_stacks.h"
#include "world_slot.h"

namespace tumble {

void World::choose_island_solvers(double dt) {
  StepScratch& s = *scratch_;
  prepare_joint_rows();  // (may add solver bodies: kinematic ones of joints' own)
  const std::uint32_t solver_bodies = static_cast<std::uint32_t>(s.solver_slot.size());
  build_islands(s.dynamic, s.links, s.joint_links, &s.islands);
  s.support_level.resize(solver_bodies);

  const std::size_t islands = s.islands.count();
  s.island_rows.clear();
  s.island_row_begin.assign(1, 0);
  s.reports.assign(islands, IslandReport{});
  const SolverSettings& solver = settings_.solver;
  // Each island's rows, in island order, on one thread: a copy of ids.
  for (std::size_t i = 0; i < islands; ++i) {
    for (std::uint32_t l = s.islands.link_begin[i]; l < s.islands.link_begin[i + 1]; ++l) {
      const std::uint32_t manifold = s.islands.links[l];
      for (std::uint32_t r = s.row_begin[manifold]; r < s.row_begin[manifold + 1]; ++r)
        s.island_rows.push_back(r);
    }
    s.island_row_begin.push_back(static_cast<std::uint32_t>(s.island_rows.size()));
  }
  // Each island's solver, over the team: islands share no body, and each writes its own report
  // and its own bodies' support levels (the level sums are a thread's working memory).
  const int threads = team_size(settings_.threads);
  s.thread_level_sums.resize(threads);
  for_indices(
      threads, islands > 64, static_cast<std::int64_t>(islands),
      [&](std::int64_t island) {
        const std::size_t i = static_cast<std::size_t>(island);
        std::vector<LevelSums>& level_sums = s.thread_level_sums[omp_get_thread_num()];
        const std::uint32_t points = s.island_row_begin[i + 1] - s.island_row_begin[i];
        IslandSolver kind = IslandSolver::kSoft;
        const auto island_bodies =
            std::span(s.islands.bodies)
                .subspan(s.islands.body_begin[i],
                         s.islands.body_begin[i + 1] - s.islands.body_begin[i]);
        const auto island_links =
            std::span(s.islands.links)
                .subspan(s.islands.link_begin[i],
                         s.islands.link_begin[i + 1] - s.islands.link_begin[i]);
        switch (solver.kind) {
          case SolverKind::kExact:
            // A dense LCP of 10 unknowns a point: past the bound, memory and pivots would grow
            // with the square and cube of the island (a pyramid of 20 is 2,360 points, 8.7 GB).
            if (points > static_cast<std::uint32_t>(solver.exact_max_island_points)) {
              kind = IslandSolver::kSoft;
              s.reports[i].exact_oversized = true;
            } else {
              kind = IslandSolver::kExact;
            }
            break;
          case SolverKind::kPgs:
            kind = IslandSolver::kPgs;
            break;
          case SolverKind::kSoft:
            kind = IslandSolver::kSoft;
            break;
          case SolverKind::kAuto: {
            // One body against statics gains nothing from solving its contacts together with
            // others' (there are none), and the soft step resolves it at a fraction of a Lemke
            // solve's cost (8-direction pyramids make 10 unknowns per point). Of the small islands
            // of several bodies, only those where the soft answer would differ pay for Lemke
            // (auto_solver.h): in a pile of like bodies, none. A body touching nothing takes the
            // plain step of dt.
            const bool alone = island_bodies.size() == 1;
            const bool small =
                points <= static_cast<std::uint32_t>(
                              std::min(solver.exact_max_points, solver.exact_max_island_points));
            const bool exact =
                points == 0 || (!alone && small &&
                                soft_would_differ(island_bodies, island_links, s.links, s.body_of,
                                                  s.dynamic, settings_.gravity.norm(), solver));
            kind = exact ? IslandSolver::kExact : IslandSolver::kSoft;
            break;
          }
        }
        // An island with joints is solved on one thread, in the soft recipe's substeps.
        s.reports[i].joints = s.islands.joint_begin[i + 1] - s.islands.joint_begin[i];
        // Exact and auto solve its joints' rows directly (joint_tree.h); exact its limits, cones
        // and contacts as one LCP each substep (exact_joints.h) while they fit its bound, auto
        // (and exact past it) soft, but for an island of few contact points where the soft ones
        // would fail (kAutoExactJointedMassRatio), which auto gives the LCP as exact does.
        s.reports[i].joint_tree = false;
        s.reports[i].joint_loop = false;
        s.reports[i].exact_joints = false;
        if (s.reports[i].joints > 0 &&
            (solver.kind == SolverKind::kExact || solver.kind == SolverKind::kAuto)) {
          s.reports[i].joint_tree = true;
          const bool auto_exact =
              solver.kind == SolverKind::kAuto && points > 0 &&
              points <= static_cast<std::uint32_t>(
                            std::min(solver.exact_max_points, solver.exact_max_island_points)) &&
              soft_would_differ(island_bodies, island_links, s.links, s.body_of, s.dynamic,
                                settings_.gravity.norm(), solver, kAutoExactJointedMassRatio);
          if ((solver.kind == SolverKind::kExact && kind == IslandSolver::kExact) || auto_exact) {
            // A bound row is one unknown, a point 2 + k: counted as points, the bound is kept
            // with room to spare.
            std::uint32_t rows = points;
            for (std::uint32_t j = s.islands.joint_begin[i]; j < s.islands.joint_begin[i + 1]; ++j)
              rows += bound_row_count(s.joint_rows[s.islands.joints[j]].joint);
            // Nothing for the LCP (no contact, no limit, no cone): the joints alone, as auto
            // solves them (the exact recipe without relaxation let a falling chain of 20 open
            // 5e-5 m at dt 1/60, and one with a 1000 times heavier end 2 cm).
            if (rows > static_cast<std::uint32_t>(solver.exact_max_island_points))
              s.reports[i].exact_oversized = !auto_exact;
            else if (rows > 0)
              s.reports[i].exact_joints = true;
          }
          kind = IslandSolver::kSoft;
        }
        if (s.reports[i].joints > 0 && kind == IslandSolver::kExact) kind = IslandSolver::kSoft;
        s.reports[i].solver = kind;
        if (kind == IslandSolver::kSoft) {
          const IslandStiffness stiffness = island_stiffness(
              island_bodies, island_links, s.links, s.touching, s.dynamic, s.body_of,
              settings_.gravity, dt, solver, &s.support_level, &level_sums);
          s.reports[i].substeps = stiffness.substeps;
          s.reports[i].contact_hertz = stiffness.contact_hertz;
          s.reports[i].stiffness_capped = stiffness.capped;
        } else if (kind == IslandSolver::kPgs) {
          bool capped = false;
          s.reports[i].pgs_iterations =
              tall_pgs_iterations(island_bodies, island_links, s.links, s.touching, s.dynamic,
                                  solver, &s.support_level, &capped);
          s.reports[i].stiffness_capped = capped;
        }
      },
      16);
  // Every thread's level sums as large as the largest any needed, so that the next step, which
  // may hand the tallest island to another thread, allocates nothing.
  std::size_t most_levels = 0;
  for (const std::vector<LevelSums>& sums : s.thread_level_sums)
    most_levels = std::max(most_levels, sums.capacity());
  for (std::vector<LevelSums>& sums : s.thread_level_sums)
    sums.reserve(most_levels);
}

}  // namespace tumble
