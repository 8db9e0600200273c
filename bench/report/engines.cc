#include "engines.h"

namespace tumble::report {
namespace {

Engine tumble(std::string label, const std::function<void(WorldSettings&)>& configure) {
  return {std::move(label), true,
          [configure](const SceneDef& scene, const bench::PeerOptions&, std::string* why_not) {
            SceneDef ours = scene;
            if (ours.world.threads == 0) ours.world.threads = 1;
            configure(ours.world);
            return bench::make_tumble(ours, why_not);
          }};
}

void solver(WorldSettings& w, SolverKind kind) {
  w.solver.kind = kind;
}

}  // namespace

std::vector<Engine> tumble_engines(bool quick) {
  std::vector<Engine> out;
  out.push_back(tumble("Tumble exact", [](WorldSettings& w) { solver(w, SolverKind::kExact); }));
  out.push_back(tumble("Tumble auto", [](WorldSettings& w) { solver(w, SolverKind::kAuto); }));
  out.push_back(tumble("Tumble soft-4", [](WorldSettings& w) { solver(w, SolverKind::kSoft); }));
  out.push_back(tumble("Tumble pgs-10", [](WorldSettings& w) { solver(w, SolverKind::kPgs); }));
  if (quick) return out;
  out.push_back(tumble("Tumble soft-8", [](WorldSettings& w) {
    solver(w, SolverKind::kSoft);
    w.solver.substeps = 8;
  }));
  out.push_back(tumble("Tumble pgs-50", [](WorldSettings& w) {
    solver(w, SolverKind::kPgs);
    w.solver.iterations = 50;
  }));
  out.push_back(tumble("Tumble auto x2", [](WorldSettings& w) {
    solver(w, SolverKind::kAuto);
    w.threads = 2;
  }));
  // One substep, one step of dt as the peers take: the joints' sections alone (a pile's soft
  // contacts need the substeps: docs/DYNAMICS.md).
  out.push_back(tumble("Tumble auto-1", [](WorldSettings& w) {
    solver(w, SolverKind::kAuto);
    w.solver.substeps = 1;
  }));
  out.back().joints_only = true;
  // Two joint position passes after the move where the default is three: what the third costs
  // and holds (SolverSettings::joint_position_passes).
  out.push_back(tumble("Tumble pgs-10 j2", [](WorldSettings& w) {
    solver(w, SolverKind::kPgs);
    w.solver.joint_position_passes = 2;
  }));
  out.back().joints_only = true;
  return out;
}

std::vector<Engine> soft_sweep_engines() {
  struct Split {
    int substeps, solve, relax;
  };
  const Split splits[] = {{4, 1, 1}, {4, 2, 1}, {4, 2, 2}, {6, 1, 1}, {8, 1, 1}, {4, 4, 4}};
  std::vector<Engine> out;
  for (const Split& split : splits) {
    const std::string label = "Tumble soft " + std::to_string(split.substeps) + "x(" +
                              std::to_string(split.solve) + "+" + std::to_string(split.relax) + ")";
    out.push_back(tumble(label, [split](WorldSettings& w) {
      solver(w, SolverKind::kSoft);
      w.solver.substeps = split.substeps;
      w.solver.soft_iterations = split.solve;
      w.solver.relax_iterations = split.relax;
    }));
  }
  return out;
}

std::vector<Engine> peer_engines() {
  std::vector<Engine> out;
#ifdef TUMBLE_HAVE_PEERS
  auto peer = [](std::string label, auto make) {
    return Engine{
        std::move(label), false,
        [make](const SceneDef& scene, const bench::PeerOptions& options, std::string* why_not) {
          const bench::PeerScene peer_scene = bench::peer_scene(scene);
          return make(peer_scene, options, why_not);
        }};
  };
  out.push_back(peer("Bullet float", bench::make_bullet));
  out.push_back(peer("Bullet double", bench::make_bullet_double));
  // Bullet's generalised coordinates (Featherstone): where the joints are trees from the world.
  out.push_back(peer("Bullet multibody", bench::make_bullet_multibody));
  out.back().joints_only = true;
  out.push_back(peer("ODE", bench::make_ode));
  // ODE's direct solver is cubic in an island's rows (a pile's contacts): the accurate choice for
  // jointed bodies, where the report measures it.
  out.push_back(peer("ODE dWorldStep", [](const bench::PeerScene& scene, bench::PeerOptions options,
                                          std::string* why_not) {
    options.ode_world_step = true;
    return bench::make_ode(scene, options, why_not);
  }));
  out.back().joints_only = true;
  out.push_back(peer("MuJoCo", bench::make_mujoco));
#endif
  return out;
}

std::vector<std::string> built_peers() {
  std::vector<std::string> names;
  for (const Engine& engine : peer_engines())
    names.push_back(engine.label);
  return names;
}

}  // namespace tumble::report
