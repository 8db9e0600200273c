// Step time and stability on the standard scenes (../shared/SCENES.md): ours with each solver,
// beside Bullet and ODE (with -DTUMBLE_BENCH_PEERS=ON) in the same run, so ratios compare like
// for like on a noisy machine. Usage: bench_dynamics [--nosleep] [scene ...] (default: pile,
// pyramid, tower, mass-ratio, slide; --nosleep keeps every body awake in Bullet and in ours).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "peers/peer_world.h"
#include "physics/world.h"
#include "scenes/standard.h"

namespace tumble::bench {

namespace {

bool g_sleeping = true;  // --nosleep: every engine keeps every body awake

void print(const RunResult& r, double reference_ms) {
  double largest = 0;
  int fast = 0;
  for (std::size_t i = 0; i < r.start.size(); ++i) {
    largest = std::max(largest, (r.end[i] - r.start[i]).norm());
    fast += r.end_velocity[i].norm() > 0.1 ? 1 : 0;
  }
  const Vec3 top = r.end.back() - r.start.back();
  const double ms = median(r.step_ms);
  std::printf("  %-20s %8.3f %6.2f %9.4f %9.4f %9.4f %7.4f %5d %4s  %s\n", r.engine.c_str(), ms,
              reference_ms > 0 ? ms / reference_ms : 0.0, top.head<2>().norm(), top.z(), largest,
              r.deepest_corner_last_second, fast, r.blew_up ? "YES" : "no", r.settings.c_str());
}

}  // namespace
}  // namespace tumble::bench

namespace tumble::bench {
namespace {

// S6: error against run time. The stop distance of a box sliding at 5 m/s with mu = 0.5 against
// the exact v0^2 / (2 mu g), for shrinking dt, beside the wall time of the whole run.
void slide_accuracy_table() {
  const double exact = 25.0 / (2 * 0.5 * 9.81);
  std::printf(
      "\nslide (S6): stop-distance error against the exact %.4f m, and wall time of 3 s "
      "simulated\n",
      exact);
  std::printf("  %-20s", "engine");
  const int rates[] = {30, 60, 120, 240, 480};
  for (int rate : rates)
    std::printf("   dt 1/%-3d        ", rate);
  std::printf("\n");
  auto row = [&](const std::string& name, auto&& runner) {
    std::printf("  %-20s", name.c_str());
    for (int rate : rates) {
      SceneDef scene = slide_scene();
      scene.dt = 1.0 / rate;
      const auto start = std::chrono::steady_clock::now();
      const RunResult r = runner(scene, 3L * rate);
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
              .count();
      const double distance = r.end[0].x() - r.start[0].x();
      std::printf("  %+6.2f%% %7.2fms ", 100 * (distance / exact - 1), ms);
    }
    std::printf("\n");
  };
#ifdef TUMBLE_HAVE_PEERS
  row("Bullet 3.24 float", [](const SceneDef& s, long n) { return run_bullet(s, n); });
  row("ODE 0.16 double", [](const SceneDef& s, long n) { return run_ode(s, n); });
  row("MuJoCo 2.2.2", [](const SceneDef& s, long n) { return run_mujoco(s, n); });
#endif
  for (SolverKind kind : {SolverKind::kExact, SolverKind::kSoft, SolverKind::kPgs})
    row("Tumble " + std::string(solver_name(kind)),
        [kind](const SceneDef& s, long n) { return run_ours(s, kind, n, 1, true); });
}

}  // namespace
}  // namespace tumble::bench

int main(int argc, char** argv) {
  using namespace tumble;
  using namespace tumble::bench;
  std::vector<std::string> names = {"pile:1000",  "pyramid:20",     "tower:20",
                                    "mass-ratio", "mass-ratio-inv", "slide"};
  std::vector<std::string> args(argv + 1, argv + argc);
  if (!args.empty() && args[0] == "--nosleep") {
    g_sleeping = false;  // ODE and MuJoCo never sleep in these runs
    args.erase(args.begin());
  }
  if (!args.empty()) names = args;
  std::printf(
      "Standard scenes (../shared/SCENES.md), dt 1/60, one thread. ms/step: median over steps;\n"
      "ratio: to Bullet in this run; top dxy/dz: the last body's displacement; largest: any "
      "body's;\n"
      "corner: deepest box corner below the ground in the last second; fast: bodies > 0.1 m/s at "
      "the end.\n");
  for (const std::string& name : names) {
    Result<SceneDef> scene = standard_scene(name);
    if (!scene) {
      std::fprintf(stderr, "%s\n", scene.error().c_str());
      return 2;
    }
    const long steps = std::lround(scene.value().duration / scene.value().dt);
    std::printf("\n%s: %zu bodies, %ld steps\n", scene.value().name.c_str(),
                scene.value().bodies.size(), steps);
    std::printf("  %-20s %8s %6s %9s %9s %9s %7s %5s %4s  %s\n", "engine", "ms/step", "ratio",
                "top dxy", "top dz", "largest", "corner", "fast", "NaN", "settings");
    std::vector<RunResult> results;
#ifdef TUMBLE_HAVE_PEERS
    results.push_back(run_bullet(scene.value(), steps, g_sleeping));
    results.push_back(run_ode(scene.value(), steps));
    // MuJoCo 2.2's preallocated arena cannot hold the pile of 1000's contacts (PEERS.md).
    if (scene.value().bodies.size() <= 500) results.push_back(run_mujoco(scene.value(), steps));
#endif
    const bool small = scene.value().bodies.size() <= 8;
    for (SolverKind kind :
         {SolverKind::kAuto, SolverKind::kSoft, SolverKind::kPgs, SolverKind::kExact}) {
      if (kind == SolverKind::kExact && !small) continue;  // Lemke on one 1000-box island: hours
      results.push_back(run_ours(scene.value(), kind, steps, 1, g_sleeping));
    }
    if (scene.value().bodies.size() > 100) {
      results.push_back(run_ours(scene.value(), SolverKind::kAuto, steps, 2, g_sleeping));
      results.back().engine += " x2";
    }
#ifdef TUMBLE_HAVE_PEERS
    const double reference = median(results[0].step_ms);
#else
    const double reference = 0;
#endif
    for (const RunResult& r : results)
      print(r, reference);
  }
  if (args.empty() && g_sleeping) slide_accuracy_table();
  return 0;
}
