// The stages of a step, in the order World::step (step_recipe.cc) runs them, each with the file
// that holds it: the one list of what a step does (Box2D v3's solver stages are the model).
// docs/DYNAMICS.md describes each; StepStats::time times them in five groups (broad phase,
// narrow phase, prepare, solve, correct positions, and continuous collision when it runs).
#pragma once

#include <omp.h>

#include <chrono>
#include <cstdint>
#include <string_view>

namespace tumble {

struct StepStage {
  std::string_view name;
  std::string_view file;  // under physics/src
  std::string_view does;
};

inline constexpr StepStage kStepStages[] = {
    {"bounds", "world.cc (compute_bounds)",
     "bounds of the moving bodies, grown by the contact margin and their motion; resting bodies "
     "keep theirs until they change"},
    {"broad phase", "world.cc (run_broad_phase), broad_phase.cc",
     "pairs of overlapping bounds: hashed grids or sweep-and-prune, in parallel"},
    {"narrow phase", "world.cc (find_contacts), collide*.cc",
     "each pair's manifold (SAT, GJK/EPA, closed forms), its record from the last step reused "
     "while the pair barely moved"},
    {"wake", "step.cc (wake_touched)",
     "sleepers touched by moving bodies wake with their islands; bounds, pairs and manifolds "
     "again for them"},
    {"bodies", "step_bodies.cc (load_solver_bodies)",
     "the solver's bodies numbered (moving ones, then the statics they touch) and loaded"},
    {"rows", "step_rows.cc (prepare_contact_rows)",
     "each manifold's rows built in parallel; each touching pair keeps its solver colour"},
    {"islands", "step_islands.cc (choose_island_solvers)",
     "islands of touching bodies, and per island its solver and the substeps or iterations a "
     "tall stack needs"},
    {"sweeps", "step_sweeps.cc (group_for_sweeps)",
     "large iterative islands coloured for the team and packed four manifolds to a vector"},
    {"solve", "step.cc (solve_islands)",
     "velocities and positions of every island: exact (Lemke), pgs or soft substeps"},
    {"correct positions", "step.cc (correct_positions)",
     "pgs islands pushed out of overlap (the soft solver needs no pass)"},
    {"continuous", "world_continuous.cc (sweep_fast_bodies)",
     "bodies that would pass through others stopped at their first impact"},
    {"store", "step.cc (finish_step)",
     "poses and velocities written back within the limits; impulses kept for the next step"},
    {"sleep", "step.cc (update_sleep)",
     "islands slower than the thresholds long enough fall asleep, keeping their contacts"},
};

inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The threads a step's parallel loops use: the world's setting, or OpenMP's default.
inline int team_size(int requested) {
  return requested > 0 ? requested : omp_get_max_threads();
}

}  // namespace tumble
