// A stability scenario as measure_stability sweeps it, and the checks every scenario shares.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "peers/simulation.h"
#include "stability.h"

namespace tumble::report {

// Judges a run step by step: "" while it passes, else the failure mode (the run stops there).
using Checker = std::function<std::string(const bench::Simulation&, double t, bool last)>;

struct Scenario {
  ScenarioInfo info;
  std::function<SceneDef(double value)> build;
  std::function<Checker(double value, const SceneDef&)> checker;
  bool ccd = false;  // peers get their continuous collision where they have it
};

std::string format(const char* pattern, double x);
std::vector<Vec3> start_positions(const SceneDef& scene);
// NaN anywhere, or a body 1000 m from where it started: every scenario fails on these first.
std::string common_failure(const bench::Simulation& sim, const std::vector<Vec3>& start);

// The joints' scenarios (joint_scenarios.cc).
std::vector<Scenario> joint_scenarios();

}  // namespace tumble::report
