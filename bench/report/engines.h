// The engines and settings the report measures: ours with each solver (and the settings swept),
// and each peer built in, all behind peers/simulation.h.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "peers/simulation.h"

namespace tumble::report {

struct Engine {
  std::string label;  // short, for tables and plot legends: "Tumble pgs-10", "ODE"
  bool ours = false;
  // Null (with the reason) when the engine cannot run the scene or is not built in.
  std::function<std::unique_ptr<bench::Simulation>(const SceneDef&, const bench::PeerOptions&,
                                                   std::string*)>
      make;
  bool joints_only = false;  // measured on the joints' scenes alone (ODE's dWorldStep)
};

// Tumble's configurations: solver, iterations, substeps, threads. `quick` keeps one of each kind.
std::vector<Engine> tumble_engines(bool quick);
// The soft solver with other splits of its work between substeps, sweeps with bias and relaxing
// sweeps (`tumble-report --sweeps`): the measurement its defaults are chosen by (docs/DYNAMICS.md).
std::vector<Engine> soft_sweep_engines();
// Bullet float and double, ODE, MuJoCo: every peer this build has (none without the packages).
std::vector<Engine> peer_engines();
// Names of the peers built in, for the report's header and the test that checks they appear.
std::vector<std::string> built_peers();

}  // namespace tumble::report
