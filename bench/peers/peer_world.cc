// Whole runs of a standard scene in any engine (peer_world.h), measured the same way through the
// Simulation interface, so that the benchmark tables and the report share one mapping per peer.
#include "peers/peer_world.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "peers/simulation.h"

namespace tumble::bench {
namespace {

RunResult run(Simulation& sim, const SceneDef& scene, long steps) {
  RunResult result;
  result.engine = sim.engine();
  result.settings = sim.settings();
  std::vector<Vec3> halves;  // boxes' half extents (zero for other shapes: no corners)
  for (const BodyDef& def : scene.bodies) {
    if (def.type != BodyType::kDynamic) continue;
    const auto* box = std::get_if<BoxDef>(&def.shape);
    halves.push_back(box != nullptr ? box->half_extents : Vec3::Zero());
  }
  const auto read = [&](std::vector<Vec3>* out, bool velocity) {
    out->clear();
    for (std::size_t i = 0; i < sim.body_count(); ++i)
      out->push_back(velocity ? sim.body(i).linear_velocity : sim.body(i).position);
  };
  read(&result.start, false);
  const long last_second = steps - std::lround(1 / scene.dt);
  for (long s = 0; s < steps; ++s) {
    const auto start = std::chrono::steady_clock::now();
    const bool ok = sim.step();
    result.step_ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count());
    if (!ok) {
      result.settings += "; STOPPED: buffers full";
      result.blew_up = true;
      break;
    }
    for (std::size_t i = 0; i < sim.body_count(); ++i) {
      const BodyState b = sim.body(i);
      if (!b.position.allFinite() || b.position.cwiseAbs().maxCoeff() > 1000) result.blew_up = true;
      if (s >= last_second && scene.world.gravity.norm() > 0 && !halves[i].isZero())
        result.deepest_corner_last_second = std::max(
            result.deepest_corner_last_second, corner_depth(b.position, b.orientation, halves[i]));
    }
  }
  read(&result.end, false);
  read(&result.end_velocity, true);
  return result;
}

using PeerMaker = std::unique_ptr<Simulation> (*)(const PeerScene&, const PeerOptions&,
                                                  std::string*);

RunResult run_peer(PeerMaker make, const char* engine, const SceneDef& scene, long steps,
                   bool sleeping) {
  const PeerScene peer = peer_scene(scene);
  PeerOptions options;
  options.sleeping = sleeping;
  std::string why_not;
  std::unique_ptr<Simulation> sim = make(peer, options, &why_not);
  if (!sim) {
    RunResult result;
    result.engine = engine;
    result.settings = "cannot run: " + why_not;
    result.blew_up = true;
    return result;
  }
  return run(*sim, scene, steps);
}

}  // namespace

double corner_depth(const Vec3& centre, const Quat& rotation, const Vec3& half) {
  double lowest = 0;
  for (int i = 0; i < 8; ++i) {
    const Vec3 c((i & 1) ? half.x() : -half.x(), (i & 2) ? half.y() : -half.y(),
                 (i & 4) ? half.z() : -half.z());
    lowest = std::min(lowest, (rotation * c + centre).z());
  }
  return -lowest;
}

RunResult run_ours(SceneDef scene, SolverKind kind, long steps, int threads, bool sleeping) {
  scene.world.solver.kind = kind;
  scene.world.solver.sleeping = sleeping;
  scene.world.threads = threads;
  std::string why_not;
  std::unique_ptr<Simulation> sim = make_tumble(scene, &why_not);
  if (!sim) {
    RunResult result;
    result.engine = "Tumble " + std::string(solver_name(kind));
    result.settings = "cannot run: " + why_not;
    result.blew_up = true;
    return result;
  }
  return run(*sim, scene, steps);
}

RunResult run_bullet(const SceneDef& scene, long steps, bool sleeping) {
  return run_peer(make_bullet, "Bullet 3.24 float", scene, steps, sleeping);
}

RunResult run_ode(const SceneDef& scene, long steps) {
  return run_peer(make_ode, "ODE 0.16 double", scene, steps, true);
}

RunResult run_mujoco(const SceneDef& scene, long steps) {
  return run_peer(make_mujoco, "MuJoCo 2.2.2", scene, steps, true);
}

}  // namespace tumble::bench
