// Stability on stiff and extreme cases: named scenarios, each swept along one axis (mass ratio,
// tower height, speed, distance from the origin, ...) until an engine fails its pass criterion.
// For every engine: the largest value it survives and how it fails at the first it does not.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "engines.h"

namespace tumble::report {

struct ScenarioInfo {
  std::string name, axis, criterion;
  std::vector<double> values;
  bool joints = false;  // reported in the joints section
};

struct StabilityRow {
  std::string scenario, engine, settings;
  double value = 0;
  bool passed = false;
  std::string failure;  // the failure mode when not passed
  double wall_seconds = 0;
};

struct StabilityOptions {
  bool quick = false;
  double time_limit = 60;  // s of wall time per run
  // Called after each run: what ran, runs done, runs in all.
  std::function<void(const std::string&, std::size_t, std::size_t)> progress;
  bool joints_only = false;  // the joints' scenes alone (tumble-report --only joints)
};

std::vector<ScenarioInfo> stability_scenarios(bool quick);

// Step time of jointed scenes (a chain of 100 links, a pile of ragdolls) in every engine that
// maps them: ms per step, or the note saying why there is none.
struct CostRow {
  std::string scene, engine, settings;
  double ms_per_step = 0;
  // How far the joints came apart (JointGaps: the largest distance between a joint's two anchors),
  // m: the largest over the run, and each step's largest averaged over the steps.
  double worst_gap = 0, mean_gap = 0;
  std::string note;
  // The engines step by turns: the median over the turns of this engine's turn time over Bullet
  // float's in the same turn (0 where Bullet float did not run).
  double ratio_to_reference = 0;
};
std::vector<CostRow> measure_joint_cost(const std::vector<Engine>& engines,
                                        const StabilityOptions& options);
// Each engine climbs each scenario's values in order and stops at its first failure.
std::vector<StabilityRow> measure_stability(const std::vector<Engine>& engines,
                                            const StabilityOptions& options);

}  // namespace tumble::report
