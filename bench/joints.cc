// Joints beside Bullet in the same run: a chain of 20 ball-jointed links (0.2 m, 0.5 kg) hanging
// from the world, its end R times heavier and pushed sideways at 1 m/s, swung 20 s: how far its
// joints come apart (the largest gap between a link's end and the next link's, or the pivot, over
// every step, read from the bodies' poses the same way for every engine) and the median step time;
// then the standard chain:100 (released level, swinging clear of the ground) and the pile of eight
// ragdolls (awake, without their joints' friction): the largest distance between a joint's two
// anchors (report::JointGaps) over the run and its mean over the steps, beside the step time, and
// Bullet again with 20, 50 and 100 iterations: what its error does with our time and more. Ours
// with the direct solve of joint trees (auto, with the default four substeps and with one) and with
// Gauss-Seidel joints (soft, pgs); Bullet 3.24 float and double (its constraint of each joint's
// kind, 10 sequential-impulse iterations) and Bullet's btMultiBody (float, generalised coordinates;
// trees from the world alone). ODE and MuJoCo join in the report's joints section (make report).
// The engines of a scene take turns of 20 steps, and each line ends with the median over the turns
// of its step time over Bullet float's in the same turn: a ratio the machine's changing speed
// moves far less than a ratio of two runs' medians (run_together).
// Usage: bench_joints [seconds] (default 20).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <initializer_list>
#include <memory>
#include <string>
#include <vector>

#include "peers/peer_world.h"
#include "peers/simulation.h"
#include "report/joint_gaps.h"
#include "scenes/standard.h"

namespace tumble::bench {
namespace {

constexpr int kLinks = 20;

SceneDef heavy_chain(double ratio, SolverKind solver) {
  SceneDef scene = hanging_chain_scene(kLinks, ratio);
  scene.world.solver.kind = solver;
  scene.world.threads = 1;
  return scene;
}

struct Run {
  double gap = 0, median_ms = 0;
  double gap_sum = 0;  // of each step's gap, for their mean
  int steps = 0;
  bool stopped = false;         // the engine reported that it cannot go on
  std::vector<double> ms;       // each timed step's time
  std::vector<double> turn_ms;  // each turn's median (run_together)
  double median_ratio = 0;      // of its turns' times to the reference's, turn by turn
};

// One engine of a group, stepped in turn with the others.
struct Entry {
  std::string name;
  std::unique_ptr<Simulation> sim;
  Run run;
};

// The engines of a group take turns, kTurnSteps steps each, so that every engine meets the
// machine at the same speeds: on a shared machine one engine's 5 s and the next's ran up to a
// quarter apart in speed, which stepping each through its whole run in turn put straight into
// their ratio. A turn's first step finds the caches full of the other engines' data and is not
// timed (taking turns a step at a time slowed Bullet's steps by half and ours by less: not the
// step either engine takes alone). Each engine's time over the reference's (`reference`: an
// entry's index, the first peer) is taken turn by turn, from the two turns' medians, and its
// median over the turns kept.
constexpr int kTurnSteps = 20;
template <class Measure>
void run_together(std::vector<Entry>& entries, int steps, Measure measure, std::size_t reference) {
  for (int first = 0; first < steps; first += kTurnSteps) {
    for (Entry& entry : entries) {
      Run& r = entry.run;
      std::vector<double> turn;
      for (int k = first; k < std::min(steps, first + kTurnSteps) && !r.stopped; ++k) {
        const auto start = std::chrono::steady_clock::now();
        if (!entry.sim->step()) {
          r.stopped = true;
          break;
        }
        const double ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        if (k > first) turn.push_back(ms);
        const double gap = measure(*entry.sim);
        r.gap = std::max(r.gap, gap);
        r.gap_sum += gap;
        ++r.steps;
      }
      if (turn.empty()) continue;
      r.ms.insert(r.ms.end(), turn.begin(), turn.end());
      r.turn_ms.push_back(median(turn));
    }
  }
  const std::vector<double>* peer =
      reference < entries.size() ? &entries[reference].run.turn_ms : nullptr;
  for (Entry& entry : entries) {
    Run& r = entry.run;
    r.median_ms = median(r.ms);
    if (peer == nullptr) continue;
    std::vector<double> ratios;
    for (std::size_t k = 0; k < std::min(r.turn_ms.size(), peer->size()); ++k)
      if ((*peer)[k] > 0) ratios.push_back(r.turn_ms[k] / (*peer)[k]);
    r.median_ratio = median(ratios);
  }
}

// One line of the table: a run's gaps and median step, its median ratio to the reference peer's
// step, and where the engine stopped early (it reported that it cannot go on), after how many
// steps: its gap covers those alone.
void print_run(const char* label, const std::string& name, const Run& r, int steps,
               const char* reference) {
  std::printf("  %-8s %-24s gap %11.3e m (mean %9.3e)  median %8.4f ms  %5.2fx %s", label,
              name.c_str(), r.gap, r.steps > 0 ? r.gap_sum / r.steps : 0.0, r.median_ms,
              r.median_ratio, reference);
  if (r.steps < steps) std::printf("  -- stopped after %d of %d steps", r.steps, steps);
  std::printf("\n");
}

// Ours as configured: the solver, and the substeps (0: the settings' default).
struct Ours {
  const char* label;
  SolverKind solver;
  int substeps;
};
// auto with one substep takes one step of dt, as the peers do: a pendulum's period error at dt
// 1/60 is then theirs (docs/PERFORMANCE.md), where the default four substeps cut it sixteenfold.
constexpr Ours kOurs[] = {{"Tumble auto (direct)", SolverKind::kAuto, 0},
                          {"Tumble auto, 1 substep", SolverKind::kAuto, 1},
                          {"Tumble soft (GS)", SolverKind::kSoft, 0},
                          {"Tumble pgs (GS)", SolverKind::kPgs, 0}};

// Every engine on `scene` (ours in each configuration of kOurs; Bullet float, double and
// multibody; and Bullet float again with each of `bullet_iterations` sequential-impulse
// iterations: how far its error falls as it is given our time and more), stepped together
// (run_together), each step's time beside Bullet float's.
template <class Make, class Measure>
void each_engine(Make make_scene, int steps, Measure measure, const char* label,
                 std::initializer_list<int> bullet_iterations = {}) {
  std::vector<Entry> entries;
  // An engine that cannot take the scene says why, in its line, and is left out.
  const auto add = [&](const std::string& name, std::unique_ptr<Simulation> sim,
                       const std::string& why) {
    if (sim)
      entries.push_back({name, std::move(sim), {}});
    else
      std::printf("  %-8s %-24s not run: %s\n", label, name.c_str(), why.c_str());
  };
  for (const Ours& ours : kOurs) {
    SceneDef scene = make_scene(ours.solver);
    if (ours.substeps > 0) scene.world.solver.substeps = ours.substeps;
    std::string why;
    auto sim = make_tumble(scene, &why);
    add(ours.label, std::move(sim), why);
  }
  const std::size_t reference = entries.size();  // Bullet float, where it runs
  const SceneDef scene = make_scene(SolverKind::kSoft);
  const PeerScene peer = peer_scene(scene);
  PeerOptions options;
  options.sleeping = false;
  for (auto [name, make] :
       {std::pair{"Bullet float", &make_bullet}, std::pair{"Bullet double", &make_bullet_double},
        std::pair{"Bullet multibody", &make_bullet_multibody}}) {
    std::string why;
    auto sim = make(peer, options, &why);
    add(name, std::move(sim), why);
  }
  for (const int iterations : bullet_iterations) {
    PeerOptions more = options;
    more.iterations = iterations;
    std::string why;
    auto sim = make_bullet(peer, more, &why);
    add("Bullet float, " + std::to_string(iterations) + " iter.", std::move(sim), why);
  }
  const bool has_reference =
      reference < entries.size() && entries[reference].name == "Bullet float";
  run_together(entries, steps, measure, has_reference ? reference : entries.size());
  for (const Entry& entry : entries)
    print_run(label, entry.name, entry.run, steps, has_reference ? "Bullet float" : "(no peer)");
}

}  // namespace
}  // namespace tumble::bench

int main(int argc, char** argv) {
  using namespace tumble;
  using namespace tumble::bench;
  const double seconds = argc > 1 ? std::atof(argv[1]) : 20;
  const int steps = static_cast<int>(seconds * 60);
  std::printf("heavy chain: 20 links hanging, end R times heavier, kicked 1 m/s, %g s\n", seconds);
  // Every ratio's chain has the same joints (a link's ends, the pivot).
  const report::JointGaps heavy_chain_gaps(hanging_chain_scene(kLinks));
  const auto heavy_chain_gap = [&](const Simulation& sim) { return heavy_chain_gaps.largest(sim); };
  for (double ratio : {1.0, 10.0, 100.0, 1000.0}) {
    char label[32];
    std::snprintf(label, sizeof label, "1:%g", ratio);
    each_engine([&](SolverKind solver) { return heavy_chain(ratio, solver); }, steps,
                heavy_chain_gap, label);
  }
  const report::JointGaps chain_gaps(chain_scene(100));
  std::printf("chain:100 (standard scene, released level), %g s: joints' anchor gap, step time\n",
              seconds);
  const auto chain = [&](SolverKind solver) {
    SceneDef scene = chain_scene(100);
    scene.world.solver.kind = solver;
    scene.world.threads = 1;
    return scene;
  };
  const auto chain_gap = [&](const Simulation& sim) { return chain_gaps.largest(sim); };
  each_engine(chain, steps, chain_gap, "chain100", {20, 50, 100});
  // The ragdoll pile awake, without its joints' friction (no peer adapter maps it).
  const report::JointGaps ragdoll_gaps(ragdolls_scene(8));
  std::printf(
      "ragdolls:8 (standard scene, awake, no joint friction), %g s: joints' anchor gap, step "
      "time\n",
      seconds);
  const auto ragdolls = [&](SolverKind solver) {
    SceneDef scene = ragdolls_scene(8);
    scene.world.solver.kind = solver;
    scene.world.solver.sleeping = false;
    scene.world.threads = 1;
    for (SceneJoint& joint : scene.joints)
      joint.def.friction = 0;
    return scene;
  };
  const auto ragdoll_gap = [&](const Simulation& sim) { return ragdoll_gaps.largest(sim); };
  each_engine(ragdolls, steps, ragdoll_gap, "ragdoll8", {20, 50, 100});
  return 0;
}
