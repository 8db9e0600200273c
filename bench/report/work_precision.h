// Error against run time: scenes with known answers (closed forms, or a converged reference run),
// each run by every engine over a sweep of time steps; the error of each run beside the wall time
// it took per simulated second.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "engines.h"

namespace tumble::report {

struct WorkPrecisionRow {
  std::string scene, engine, settings;
  double dt = 0;               // s
  double error = 0;            // in the scene's unit (relative, or m); NaN when it blew up
  double wall_per_second = 0;  // s of wall time per simulated second
  std::string note;            // why there is no number ("not supported: ...")
};

struct ReferenceInfo {
  std::string name, what, reference, unit;
  bool joints = false;  // reported in the joints section
};

struct WorkPrecisionOptions {
  bool quick = false;
  double time_limit = 60;  // s of wall time per run
  // Called after each run: what ran, runs done, runs in all.
  std::function<void(const std::string&, std::size_t, std::size_t)> progress;
  bool joints_only = false;  // the joints' scenes alone (tumble-report --only joints)
};

// The scenes, in report order, with what their error measures and against what.
std::vector<ReferenceInfo> reference_scenes(bool quick);
// Every scene x engine x dt (dt from 1/30 to 1/960 s; quick: to 1/240).
std::vector<WorkPrecisionRow> measure_work_precision(const std::vector<Engine>& engines,
                                                     const WorkPrecisionOptions& options);
// The time steps swept, 1/s.
std::vector<int> swept_rates(bool quick);

}  // namespace tumble::report
