// Ours on a standard scene, measured as the peers are (peer_world.h).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "peers/peer_world.h"
#include "physics/world.h"

namespace tumble::bench {

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
  World world = make_world(scene).value();
  RunResult result;
  result.engine = "Tumble " + std::string(solver_name(kind));
  const SolverSettings& s = scene.world.solver;
  char settings[160];
  std::snprintf(
      settings, sizeof settings, "%s; %d thread%s",
      kind == SolverKind::kSoft ? ("soft, " + std::to_string(s.substeps) + " substeps x " +
                                   std::to_string(s.soft_iterations) + " iterations")
                                      .c_str()
      : kind == SolverKind::kPgs ? ("pgs, " + std::to_string(s.iterations) + " iterations").c_str()
      : kind == SolverKind::kAuto
          ? ("exact <= " + std::to_string(s.exact_max_points) + " points per island, else soft")
                .c_str()
          : "Lemke, 8-sided friction pyramid",
      threads, threads > 1 ? "s" : "");
  result.settings = settings;
  std::vector<std::uint32_t> slots;
  for (std::uint32_t i = 0; i < world.slot_count(); ++i)
    if (const Body* b = world.body(world.id_at(i)); b && !b->is_static()) slots.push_back(i);
  auto body = [&](std::uint32_t slot) { return world.body(world.id_at(slot)); };
  for (std::uint32_t slot : slots)
    result.start.push_back(body(slot)->position);
  const long last_second = steps - std::lround(1 / scene.dt);
  for (long step = 0; step < steps; ++step) {
    const auto start = std::chrono::steady_clock::now();
    world.step(scene.dt);
    result.step_ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count());
    for (std::uint32_t slot : slots) {
      const Body* b = body(slot);
      if (!b->position.allFinite() || b->position.cwiseAbs().maxCoeff() > 1000)
        result.blew_up = true;
      if (step >= last_second && scene.world.gravity.norm() > 0 &&
          b->shape.type() == ShapeType::kBox)
        result.deepest_corner_last_second =
            std::max(result.deepest_corner_last_second,
                     corner_depth(b->position, b->orientation, b->shape.half_extents()));
    }
  }
  for (std::uint32_t slot : slots) {
    result.end.push_back(body(slot)->position);
    result.end_velocity.push_back(body(slot)->linear_velocity);
  }
  return result;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

}  // namespace tumble::bench
