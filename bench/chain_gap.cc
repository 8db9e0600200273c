// The report's chain-gap measure over nudged starts. The report (bench/report/joint_references.cc)
// drops a chain of 20 ball-jointed links from level once and keeps the largest gap any joint
// shows in 10 s. Once the chain lands in a heap on the ground its contacts make the run chaotic:
// a change of the last bit anywhere (another order of the same arithmetic) gives another heap, and
// the largest gap of that one run moves by a decade or two. This runs the same scene from STARTS
// starts, each body's start moved by up to 1e-9 m (start 0 unmoved), and prints each run's largest
// gap with their median and largest: a figure two builds can be compared by.
//
// Usage: bench_chain_gap [RATE [SECONDS [STARTS [SUBSTEPS]]]]
//   RATE      steps a second (default 60)
//   SECONDS   simulated (default 10, as the report)
//   STARTS    nudged starts (default 40)
//   SUBSTEPS  the solver's substeps (default: the scene's, 4)
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include "scenes/scene.h"
#include "scenes/standard.h"

using namespace tumble;

int main(int argc, char** argv) {
  const double rate = argc > 1 ? std::atof(argv[1]) : 60;
  const double seconds = argc > 2 ? std::atof(argv[2]) : 10;
  const int starts = argc > 3 ? std::atoi(argv[3]) : 40;
  const int substeps = argc > 4 ? std::atoi(argv[4]) : 0;
  if (!(rate >= 1 && rate <= 10000) || !(seconds > 0 && seconds <= 1000) || starts < 1 ||
      starts > 1000 || substeps < 0 || substeps > 32) {
    std::fprintf(stderr,
                 "usage: bench_chain_gap [RATE 1-10000 [SECONDS 0-1000 [STARTS 1-1000 "
                 "[SUBSTEPS 0-32]]]]\n");
    return 2;
  }
  const double dt = 1 / rate;
  const int steps = static_cast<int>(seconds * rate + 0.5);
  std::vector<double> largest;
  for (int start = 0; start < starts; ++start) {
    SceneDef scene = chain_scene(20);
    scene.world.solver.sleeping = false;
    scene.world.threads = 1;
    if (substeps > 0) scene.world.solver.substeps = substeps;
    std::mt19937_64 rng(start);
    std::uniform_real_distribution<double> nudge(-1e-9, 1e-9);
    if (start > 0)
      for (BodyDef& body : scene.bodies)
        body.position += Vec3(nudge(rng), nudge(rng), nudge(rng));
    Result<World> made = make_world(scene);
    if (!made.ok()) {
      std::fprintf(stderr, "bench_chain_gap: %s\n", made.status().message().c_str());
      return 1;
    }
    World& world = made.value();
    double worst = 0;
    for (int k = 0; k < steps; ++k) {
      if (!world.step(dt).is_ok()) {
        std::fprintf(stderr, "bench_chain_gap: a step failed\n");
        return 1;
      }
      worst = std::max(worst, world.last_step().joint_error);
    }
    largest.push_back(worst);
  }
  std::vector<double> sorted = largest;
  std::sort(sorted.begin(), sorted.end());
  std::printf("chain of 20 released level, dt 1/%g, %g s, %d starts nudged by up to 1e-9 m:\n",
              rate, seconds, starts);
  std::printf("largest joint gap of each run (m):");
  for (double gap : largest)
    std::printf(" %.1e", gap);
  std::printf("\nmedian %.2e  largest %.2e  smallest %.2e\n", sorted[sorted.size() / 2],
              sorted.back(), sorted.front());
  return 0;
}
