// Whole runs of the standard scenes of ../shared/SCENES.md in ours and in the peer engines (through
// simulation.h, with the settings SCENES.md gives for each), so their times and stability sit
// beside ours in the benchmark tables.
#pragma once

#include <string>
#include <vector>

#include "physics/math.h"
#include "physics/step.h"
#include "scenes/scene.h"
#include "timing.h"  // median

namespace tumble::bench {

// What every engine reports after a run, read the same way from each.
struct RunResult {
  std::string engine, settings;
  std::vector<double> step_ms;   // wall time of each step
  std::vector<Vec3> start, end;  // dynamic bodies' centres, scene order
  std::vector<Vec3> end_velocity;
  double deepest_corner_last_second = 0;  // m below z = 0
  bool blew_up = false;                   // NaN or a coordinate beyond 1000 m
};

// A box's deepest corner below z = 0 (0 when above), from its centre, rotation and half extents.
double corner_depth(const Vec3& centre, const Quat& rotation, const Vec3& half);

// Ours with one solver, `threads` OpenMP threads; `sleeping` as below.
RunResult run_ours(SceneDef scene, SolverKind kind, long steps, int threads, bool sleeping);

// `sleeping` false keeps every body awake (Bullet: DISABLE_DEACTIVATION; ours: solver.sleeping).
RunResult run_bullet(const SceneDef& scene, long steps, bool sleeping = true);
RunResult run_ode(const SceneDef& scene, long steps);
RunResult run_mujoco(const SceneDef& scene,
                     long steps);  // boxes and a plane; no pile of 1000 (see PEERS.md)

}  // namespace tumble::bench
