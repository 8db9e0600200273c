// tumble-run: steps a scene (the embedded default, a JSON file or a standard scene) and prints,
// once per simulated second, what the world is doing: contacts (with those of sleeping bodies,
// which still rest on each other), islands solved, the fastest body, the deepest penetration, the
// solver's residual and the cost of a step.
#include <omp.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include <string>

#include "physics/world.h"
#include "scenes/scene.h"
#include "scenes/standard.h"
#include "tumble/command_line.h"
#include "tumble/passive_wait.h"

using namespace tumble;

namespace {

struct Totals {
  double kinetic = 0, potential = 0, max_speed = 0;
};

Totals measure(const World& world) {
  Totals t;
  const Vec3 g = world.settings().gravity;
  for (std::uint32_t i = 0; i < world.slot_count(); ++i) {
    const BodyView body = world.body(world.id_at(i));
    if (!body || body->is_static()) continue;
    const Vec3 w_body = body->orientation().conjugate() * body->angular_velocity();
    t.kinetic += 0.5 * body->mass() * body->linear_velocity().squaredNorm() +
                 0.5 * w_body.dot(body->inertia_body() * w_body);
    t.potential -= body->mass() * g.dot(body->position());
    t.max_speed = std::max(t.max_speed, body->linear_velocity().norm());
  }
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  tumble::cli::wait_passively_by_default(argv);  // first: it may run the program again
  CLI::App app{"Steps a Tumble scene and prints what happens, once per simulated second."};
  cli::keep_conventions(app, "tumble-run");
  std::string scene_file, standard;
  std::string solver;
  double duration = -1;
  int threads = -1;
  app.add_option("--scene", scene_file, "a scene file (JSON, see docs/SCENES.md)");
  app.add_option("--standard", standard,
                 "a standard scene: pile[:N], pyramid[:N], tower[:N], mass-ratio, mass-ratio-inv, "
                 "bullet, slide, spin, bounce, pendulum, double-pendulum, chain[:N[:R]], cradle, "
                 "door, rope-bridge[:N], arm, ragdolls[:N], default (docs/SCENES.md)");
  app.add_option("--solver", solver, "exact, pgs, soft or auto (default: the scene's)");
  app.add_option("--duration", duration, "simulated seconds (default: the scene's)");
  app.add_option("--threads", threads, "OpenMP threads (0 = all; default: the scene's)")
      ->check(cli::non_negative)
      ->check(CLI::Range(0, 1024));
  bool no_sleep = false;
  app.add_flag("--no-sleep", no_sleep, "keep every body awake");
  double manifold_reuse = -1;
  app.add_option("--manifold-reuse", manifold_reuse,
                 "pairs of polytopes that moved less than this share of their size keep their "
                 "feature (0 to 0.01; 0 searches every step; default: the scene's)");
  if (const int exit_status = cli::parse(app, argc, argv); exit_status >= 0) return exit_status;

  Result<SceneDef> scene = chosen_scene(scene_file, standard);
  if (!scene) {
    std::fprintf(stderr, "tumble-run: %s\n", scene.error().c_str());
    return 2;
  }
  SceneDef& def = scene.value();
  if (!solver.empty()) {
    const auto kind = solver_from_name(solver);
    if (!kind) {
      std::fprintf(stderr, "tumble-run: --solver: unknown solver '%s' (exact, pgs, soft, auto)\n",
                   solver.c_str());
      return 2;
    }
    def.world.solver.kind = *kind;
  }
  if (duration >= 0) def.duration = duration;
  if (threads >= 0) def.world.threads = threads;
  if (no_sleep) def.world.solver.sleeping = false;
  if (app.count("--manifold-reuse") > 0) def.world.solver.manifold_reuse = manifold_reuse;
  Result<World> made = make_world(def);
  if (!made) {
    std::fprintf(stderr, "tumble-run: %s\n", made.error().c_str());
    return 2;
  }
  World& world = made.value();

  const long steps = std::lround(def.duration / def.dt);
  const long per_second = std::max(1L, std::lround(1 / def.dt));
  const char* wait_policy = std::getenv("OMP_WAIT_POLICY");
  std::printf("scene %s: %zu bodies, dt %.6g s, %ld steps, solver %s, %d threads waiting %s\n",
              def.name.c_str(), world.body_count(), def.dt, steps,
              std::string(solver_name(def.world.solver.kind)).c_str(),
              def.world.threads > 0 ? def.world.threads : omp_get_max_threads(),
              wait_policy != nullptr ? wait_policy : "as libgomp chooses");
  std::printf("%7s %9s %8s %8s %7s %10s %12s %12s %10s %9s\n", "t [s]", "contacts", "islands",
              "exact", "asleep", "max |v|", "penetration", "energy [J]", "residual", "ms/step");
  StageTimes stage_sums;
  // Bounded loops that hit their bound, summed over the run: none of their answers was used as if
  // it were right, but a run that hits them is one to look at.
  std::uint64_t exact_fallbacks = 0, exact_oversized = 0, gyroscopic = 0, continuous = 0,
                pair_bound = 0;
  // Islands tall enough to buckle, given more substeps or sweeps (island-steps), and those at the
  // bound.
  std::uint64_t stiffened = 0, stiffness_capped = 0;
  // The world's limits held by the step (body-steps).
  std::uint64_t non_finite = 0, slowed = 0, at_edge = 0;
  // Manifold-steps, and those swept in SIMD lanes (contact packs; none without AVX2).
  std::uint64_t manifolds = 0, packed = 0, reused = 0;
  double window_seconds = 0;
  int window_steps = 0;
  const auto start = std::chrono::steady_clock::now();
  for (long s = 1; s <= steps; ++s) {
    if (Status status = world.step(def.dt); !status) {
      std::fprintf(stderr, "tumble-run: %s\n", status.message().c_str());
      return 1;
    }
    const StageTimes& times = world.last_step().time;
    exact_fallbacks += world.last_step().exact_fallbacks;
    exact_oversized += world.last_step().exact_oversized;
    gyroscopic += world.last_step().gyroscopic_limit_hits;
    continuous += world.last_step().continuous_limit_hits;
    pair_bound += world.last_step().pair_limit_hits;
    stiffened += world.last_step().stiffened_islands;
    stiffness_capped += world.last_step().stiffness_capped;
    non_finite += world.last_step().non_finite_bodies;
    slowed += world.last_step().slowed_bodies;
    at_edge += world.last_step().bodies_at_edge;
    manifolds += world.last_step().manifolds;
    packed += world.last_step().packed_manifolds;
    reused += world.last_step().reused_manifolds;
    window_seconds += times.total;
    stage_sums.broad_phase += times.broad_phase;
    stage_sums.narrow_phase += times.narrow_phase;
    stage_sums.prepare += times.prepare;
    stage_sums.solve += times.solve;
    stage_sums.correct_positions += times.correct_positions;
    stage_sums.continuous += times.continuous;
    stage_sums.total += times.total;
    ++window_steps;
    if (s % per_second == 0 || s == steps) {
      const StepStats& st = world.last_step();
      const Totals t = measure(world);
      std::printf("%7.2f %9u %8u %8u %7u %10.4f %12.2e %12.4f %10.2e %9.3f\n", world.time(),
                  st.contact_points + st.resting_contact_points, st.islands, st.exact_islands,
                  st.sleeping_bodies, t.max_speed, st.max_penetration, t.kinetic + t.potential,
                  st.residual, 1e3 * window_seconds / window_steps);
      window_seconds = 0;
      window_steps = 0;
    }
  }
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("%ld steps in %.3f s of wall time (%.3f ms per step)\n", steps, wall,
              1e3 * wall / std::max(1L, steps));
  const double per_step = 1e3 / std::max(1L, steps);
  std::printf(
      "mean ms per step by stage: broad %.3f, narrow %.3f, prepare %.3f, solve %.3f, "
      "correct %.3f, continuous %.3f, other %.3f\n",
      per_step * stage_sums.broad_phase, per_step * stage_sums.narrow_phase,
      per_step * stage_sums.prepare, per_step * stage_sums.solve,
      per_step * stage_sums.correct_positions, per_step * stage_sums.continuous,
      per_step * (stage_sums.total - stage_sums.broad_phase - stage_sums.narrow_phase -
                  stage_sums.prepare - stage_sums.solve - stage_sums.correct_positions -
                  stage_sums.continuous));
  const auto share = [&](std::uint64_t part) {
    return manifolds > 0 ? 100.0 * static_cast<double>(part) / static_cast<double>(manifolds) : 0.0;
  };
  std::printf(
      "contact manifolds swept in SIMD lanes (packs): %.1f%% of %llu manifold-steps; clipped on "
      "a kept feature (the pair barely moved): %.1f%%\n",
      share(packed), static_cast<unsigned long long>(manifolds), share(reused));
  std::printf(
      "bounds hit over the run: exact islands solved by pgs instead %llu, exact islands too large "
      "(soft) %llu, gyroscopic steps kept as spin %llu, swept pairs stopped at the bound %llu, "
      "steps with more pairs than the bound (heaped bodies) %llu\n",
      static_cast<unsigned long long>(exact_fallbacks),
      static_cast<unsigned long long>(exact_oversized), static_cast<unsigned long long>(gyroscopic),
      static_cast<unsigned long long>(continuous), static_cast<unsigned long long>(pair_bound));
  std::printf(
      "tall stacks over the run (island-steps): given more substeps (soft) or sweeps (pgs) %llu, "
      "needing more than the bound (32 substeps, 256 sweeps) %llu\n",
      static_cast<unsigned long long>(stiffened),
      static_cast<unsigned long long>(stiffness_capped));
  std::printf(
      "limits held over the run (body-steps): non-finite results kept at rest %llu, slowed to the "
      "speed limits %llu, held at the edge of the world %llu\n",
      static_cast<unsigned long long>(non_finite), static_cast<unsigned long long>(slowed),
      static_cast<unsigned long long>(at_edge));
  return 0;
}
