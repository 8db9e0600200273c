// The recipe of a step: World::step runs the stages of kStepStages (step_stages.h) in order,
// each a function in its own file, and times them into StepStats. Read this file as the table
// of contents of a step; docs/DYNAMICS.md describes each stage.
#include <chrono>
#include <utility>

#include "parallel.h"
#include "physics/world.h"
#include "step_stages.h"
#include "world_slot.h"

namespace tumble {

Status World::step(double dt) {
  if (Status s = check_time_step(dt, settings_.limits); !s) return s;
  const auto start = std::chrono::steady_clock::now();
  ++query_version_;  // the bodies move
  const std::uint64_t step_index = stats_.step + 1;
  stats_ = StepStats{};
  stats_.step = step_index;
  // The team regions' times, each stage's read off as it ends (parallel.h).
  RegionClock regions;
  const RegionClockScope clock_scope(&regions);
  const auto regions_since = [&regions](double* parallel, double* idle) {
    *parallel += std::exchange(regions.region_seconds, 0.0);
    *idle += std::exchange(regions.idle_thread_seconds, 0.0);
  };
  StageTimes& parallel = stats_.parallel_time;
  StageTimes& idle = stats_.idle_time;

  // Sleepers joined to moving bodies move with them (before the bounds, which count them).
  if (joint_count_ > 0) stats_.woken_bodies += wake_jointed();
  auto stage = std::chrono::steady_clock::now();
  compute_bounds(dt);
  run_broad_phase();
  stats_.time.broad_phase = seconds_since(stage);
  regions_since(&parallel.broad_phase, &idle.broad_phase);

  stage = std::chrono::steady_clock::now();
  find_contacts(dt);
  stats_.time.narrow_phase = seconds_since(stage);

  // Sleepers touched by moving bodies wake with their islands, and the woken need their own
  // contacts this step. Islands that touch fall asleep together, so one more pass finds them all.
  if (const std::uint32_t woken = wake_touched(); woken > 0) {
    stats_.woken_bodies += woken;
    stage = std::chrono::steady_clock::now();
    compute_bounds(dt);
    run_broad_phase();
    find_contacts(dt);
    stats_.time.narrow_phase += seconds_since(stage);
  }
  regions_since(&parallel.narrow_phase, &idle.narrow_phase);

  stage = std::chrono::steady_clock::now();
  load_solver_bodies();
  prepare_contact_rows();
  choose_island_solvers(dt);
  group_for_sweeps();
  stats_.time.prepare = seconds_since(stage);
  regions_since(&parallel.prepare, &idle.prepare);

  stage = std::chrono::steady_clock::now();
  solve_islands(dt);
  stats_.time.solve = seconds_since(stage);
  regions_since(&parallel.solve, &idle.solve);

  stage = std::chrono::steady_clock::now();
  correct_positions(dt);
  stats_.time.correct_positions = seconds_since(stage);
  regions_since(&parallel.correct_positions, &idle.correct_positions);

  if (fast_count_ > 0) {
    stage = std::chrono::steady_clock::now();
    sweep_fast_bodies(dt);
    stats_.time.continuous = seconds_since(stage);
    regions_since(&parallel.continuous, &idle.continuous);
  }

  finish_step(dt);
  update_sleep(dt);
  stats_.time.total = seconds_since(start);
  regions_since(&parallel.total, &idle.total);
  // The total adds the stages' to what ran after them (store, sleep).
  for (StageTimes* times : {&parallel, &idle})
    times->total += times->broad_phase + times->narrow_phase + times->prepare + times->solve +
                    times->correct_positions + times->continuous;
  return Status::ok();
}

}  // namespace tumble
