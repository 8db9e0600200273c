// How the step's cost grows with the pile (S1 of ../shared/SCENES.md at 1000, 4000 and 16000
// boxes) and what a second thread buys, beside Bullet, ODE and MuJoCo in the same run.
// Usage: bench_scale [--steps N] [--nosleep] [N ...] (default: 600 steps, piles 1000 4000 16000).
#include <cstdio>
#include <cstdlib>
#include <numeric>
#include <string>
#include <vector>

#include "peers/peer_world.h"
#include "scenes/standard.h"

using namespace tumble;
using namespace tumble::bench;

namespace {

double mean(const std::vector<double>& v) {
  return v.empty() ? 0 : std::accumulate(v.begin(), v.end(), 0.0) / v.size();
}

void print(const RunResult& r, int threads, std::size_t bodies, double reference_ms,
           double one_thread_ms) {
  const double ms = median(r.step_ms);
  int fast = 0;
  for (const Vec3& v : r.end_velocity)
    fast += v.norm() > 0.1 ? 1 : 0;
  char speedup[16] = "";
  if (one_thread_ms > 0) std::snprintf(speedup, sizeof speedup, "%.2fx", one_thread_ms / ms);
  std::printf("  %-20s %7d %9.3f %9.3f %10.3f %6.2f %8s %5d %4s  %s\n", r.engine.c_str(), threads,
              ms, mean(r.step_ms), 1e3 * ms / bodies, reference_ms > 0 ? ms / reference_ms : 0.0,
              speedup, fast, r.blew_up ? "YES" : "no", r.settings.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  long steps = 600;
  bool sleeping = true;
  std::vector<int> sizes;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--steps" && i + 1 < argc) {
      steps = std::atol(argv[++i]);
    } else if (arg == "--nosleep") {
      sleeping = false;
    } else if (std::atoi(arg.c_str()) > 0) {
      sizes.push_back(std::atoi(arg.c_str()));
    } else {
      std::fprintf(stderr, "usage: bench_scale [--steps N] [--nosleep] [boxes ...]\n");
      return 2;
    }
  }
  if (sizes.empty()) sizes = {1000, 4000, 16000};
  std::printf(
      "Piles (S1), dt 1/60, %ld steps, sleeping %s. ms/step: median and mean over steps; us/body:\n"
      "median per box; ratio: to Bullet's median in this run; speedup: ours at 1 thread over "
      "this row;\nfast: boxes > 0.1 m/s at the end.\n",
      steps, sleeping ? "on (as SCENES.md runs Bullet)" : "off");
  for (int size : sizes) {
    const SceneDef scene = pile_scene(size);
    std::printf("\npile-%d\n  %-20s %7s %9s %9s %10s %6s %8s %5s %4s  %s\n", size, "engine",
                "threads", "median", "mean", "us/body", "ratio", "speedup", "fast", "NaN",
                "settings");
    double reference = 0;
#ifdef TUMBLE_HAVE_PEERS
    const RunResult bullet = run_bullet(scene, steps, sleeping);
    reference = median(bullet.step_ms);
    // Debian's Bullet has no multithreaded world; ODE's threading was slower than one thread on
    // the pile (PEERS.md), and MuJoCo 2.2 has no threads: one thread each.
    print(bullet, 1, size, reference, 0);
    print(run_ode(scene, steps), 1, size, reference, 0);
    std::printf(
        "  %-20s %7d %9s  cannot hold the pile's contacts in its preallocated arena "
        "(PEERS.md)\n",
        "MuJoCo 2.2.2", 1, "-");
#endif
    const RunResult one = run_ours(scene, SolverKind::kAuto, steps, 1, sleeping);
    const double one_ms = median(one.step_ms);
    print(one, 1, size, reference, 0);
    RunResult two = run_ours(scene, SolverKind::kAuto, steps, 2, sleeping);
    print(two, 2, size, reference, one_ms);
    std::fflush(stdout);
  }
  return 0;
}
