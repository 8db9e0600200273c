// Bodies of parts beside Bullet in the same run: the standard pile with each box a compound
// (compound-pile:N: jacks of three crossing bars and dumbbells of two balls on a bar, in turn)
// dropped on the ground, the whole 10 s run of each engine, alternated round by round: the median
// time per step, the ratio to Bullet 3.24 float (btCompoundShape, 10 sequential-impulse
// iterations) and to our own pile of single boxes (pile:N, what the parts cost), and how the pile
// ended: bodies whose centre went under the ground, sampled after every step untimed (through),
// and the fastest body at the end (a pile that blew up does not come to rest).
//
// Usage: bench_compounds [BODIES [ROUNDS]]   (defaults 1000, 3; one thread)
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "peers/simulation.h"
#include "scenes/standard.h"
#include "timing.h"

namespace tumble::bench {
namespace {

struct Run {
  std::vector<double> ms;  // per step
  int through = 0;
  double fastest = 0;
  bool ran = false;
  bool stopped = false;  // the engine reported that it cannot go on: ms holds the steps it took
  std::string why_not;
};

Run run(Simulation* sim, int steps) {
  Run r;
  std::vector<std::uint8_t> under(sim->body_count(), 0);
  for (int k = 0; k < steps; ++k) {
    const auto start = std::chrono::steady_clock::now();
    if (!sim->step()) {
      r.stopped = true;
      break;
    }
    r.ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count());
    for (std::size_t i = 0; i < sim->body_count(); ++i)
      if (!(sim->body(i).position.z() > 0)) under[i] = 1;
  }
  for (std::size_t i = 0; i < sim->body_count(); ++i) {
    r.through += under[i];
    r.fastest = std::max(r.fastest, sim->body(i).linear_velocity.norm());
    if (!std::isfinite(sim->body(i).position.norm())) r.fastest = INFINITY;
  }
  r.ran = true;
  return r;
}

}  // namespace
}  // namespace tumble::bench

int main(int argc, char** argv) {
  using namespace tumble;
  using namespace tumble::bench;
  const int bodies = argc > 1 ? std::atoi(argv[1]) : 1000;
  const int rounds = argc > 2 ? std::atoi(argv[2]) : 3;
  if (bodies < 1 || bodies > 100000 || rounds < 1 || rounds > 100) {
    std::fprintf(stderr, "usage: bench_compounds [BODIES 1..100000 [ROUNDS 1..100]]\n");
    return 2;
  }
  SceneDef compounds = compound_pile_scene(bodies);
  SceneDef boxes = pile_scene(bodies);
  compounds.world.threads = boxes.world.threads = 1;
  const int steps = static_cast<int>(compounds.duration / compounds.dt + 0.5);
  const PeerScene peer = peer_scene(compounds);
  PeerOptions options;  // Bullet sleeps as ours does
  struct Engine {
    const char* label;
    std::vector<double> ms;
    Run last;
  };
  std::vector<Engine> engines = {{"Tumble auto, compounds", {}, {}},
                                 {"Bullet 3.24 float, btCompoundShape", {}, {}},
                                 {"Tumble auto, single boxes (pile)", {}, {}}};
  for (int round = 0; round < rounds; ++round) {
    for (std::size_t e = 0; e < engines.size(); ++e) {
      std::string why;
      std::unique_ptr<Simulation> sim = e == 0   ? make_tumble(compounds, &why)
                                        : e == 1 ? make_bullet(peer, options, &why)
                                                 : make_tumble(boxes, &why);
      if (!sim) {
        engines[e].last.why_not = why;
        continue;
      }
      engines[e].last = run(sim.get(), steps);
      engines[e].ms.insert(engines[e].ms.end(), engines[e].last.ms.begin(),
                           engines[e].last.ms.end());
    }
  }
  std::printf(
      "compound-pile:%d (jacks and dumbbells, 1 kg each) on the ground, %d steps of 1/60 s, "
      "%d rounds, one thread\n",
      bodies, steps, rounds);
  const double ours = median(engines[0].ms);
  for (const Engine& e : engines) {
    if (!e.last.ran) {
      std::printf("  %-36s not run: %s\n", e.label, e.last.why_not.c_str());
      continue;
    }
    const double m = median(e.ms);
    std::printf(
        "  %-36s median %8.3f ms/step  (ours / this %.2f)  through %d  fastest at the "
        "end %.3g m/s%s\n",
        e.label, m, m > 0 ? ours / m : 0.0, e.last.through, e.last.fastest,
        e.last.stopped ? "  (stopped early: the median of the steps taken)" : "");
  }
  return 0;
}
