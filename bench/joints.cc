// Joints beside Bullet in the same run: a chain of 20 ball-jointed links (0.2 m, 0.5 kg) hanging
// from the world, its end R times heavier and pushed sideways at 1 m/s, swung 20 s: how far its
// joints come apart (the largest gap between a link's end and the next link's, or the pivot, over
// every step, read from the bodies' poses the same way for every engine) and the median step time;
// then the standard chain:100 (released level, swinging clear of the ground) and the pile of eight
// ragdolls (awake, without their joints' friction): the largest distance between a joint's two
// anchors (report::JointGaps) over the run and its mean over the steps, beside the step time, and
// Bullet again with 20, 50 and 100 iterations: what its error does with our time and more. Ours
// with the direct solve of joint trees (auto, with the default four substeps and with one) and with
// Gauss-Seidel joints (soft; pgs, and pgs with two joint position passes where the default is
// three); Bullet 3.24 float and double (its constraint of each joint's kind, 10 sequential-impulse
// iterations) and Bullet's btMultiBody (float, generalised coordinates; trees from the world
// alone). ODE and MuJoCo join in the report's joints section (make report).
// The engines of a scene take turns of 20 steps, and each line ends with the median over the turns
// of its step time over Bullet float's in the same turn: a ratio the machine's changing speed
// moves far less than a ratio of two runs' medians (timing.h, take_turns).
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
#include "timing.h"

namespace tumble::bench {
namespace {

constexpr int kLinks = 20;

SceneDef heavy_chain(double ratio, SolverKind solver) {
  SceneDef scene = hanging_chain_scene(kLinks, ratio);
  scene.world.solver.kind = solver;
  scene.world.threads = 1;
  return scene;
}

// One engine of a group, stepped in turn with the others (take_turns), and its error.
struct Entry {
  std::string name;
  std::unique_ptr<Simulation> sim;
  double gap = 0;
  double gap_sum = 0;  // of each step's gap, for their mean
};

// One line of the table: an engine's gaps and median step, its median ratio to the reference
// peer's step turn by turn (`ratio`), and where the engine stopped early (it reported that it
// cannot go on), after how many steps: its gap covers those alone.
void print_run(const char* label, const Entry& entry, const TurnTimes& times, double ratio,
               long steps, const char* reference) {
  std::printf("  %-8s %-24s gap %11.3e m (mean %9.3e)  median %8.4f ms  %5.2fx %s", label,
              entry.name.c_str(), entry.gap,
              times.steps > 0 ? entry.gap_sum / static_cast<double>(times.steps) : 0.0,
              median(times.step_ms), ratio, reference);
  if (times.steps < steps) std::printf("  -- stopped after %ld of %ld steps", times.steps, steps);
  std::printf("\n");
}

// Ours as configured: the solver, the substeps and the joint position passes (0 and -1: the
// settings' defaults).
struct Ours {
  const char* label;
  SolverKind solver;
  int substeps;
  int joint_passes = -1;
};
// auto with one substep takes one step of dt, as the peers do: a pendulum's period error at dt
// 1/60 is then theirs (docs/PERFORMANCE.md), where the default four substeps cut it sixteenfold.
// pgs with two joint passes after its move where the default is three: what the third costs and
// holds (SolverSettings::joint_position_passes).
constexpr Ours kOurs[] = {{"Tumble auto (direct)", SolverKind::kAuto, 0},
                          {"Tumble auto, 1 substep", SolverKind::kAuto, 1},
                          {"Tumble soft (GS)", SolverKind::kSoft, 0},
                          {"Tumble pgs (GS)", SolverKind::kPgs, 0},
                          {"Tumble pgs, 2 passes", SolverKind::kPgs, 0, 2}};

// Every engine on `scene` (ours in each configuration of kOurs; Bullet float, double and
// multibody; and Bullet float again with each of `bullet_iterations` sequential-impulse
// iterations: how far its error falls as it is given our time and more), stepped together
// (take_turns), each step's time beside Bullet float's.
template <class Make, class Measure>
void each_engine(Make make_scene, int steps, Measure measure, const char* label,
                 std::initializer_list<int> bullet_iterations = {}) {
  std::vector<Entry> entries;
  // An engine that cannot take the scene says why, in its line, and is left out.
  const auto add = [&](const std::string& name, std::unique_ptr<Simulation> sim,
                       const std::string& why) {
    if (sim)
      entries.push_back({name, std::move(sim)});
    else
      std::printf("  %-8s %-24s not run: %s\n", label, name.c_str(), why.c_str());
  };
  for (const Ours& ours : kOurs) {
    SceneDef scene = make_scene(ours.solver);
    if (ours.substeps > 0) scene.world.solver.substeps = ours.substeps;
    if (ours.joint_passes >= 0) scene.world.solver.joint_position_passes = ours.joint_passes;
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
  std::vector<TurnTimes> times(entries.size());
  take_turns(
      std::span<TurnTimes>(times), steps,
      [&](std::size_t i, long) { return entries[i].sim->step(); },
      [&](std::size_t i, long, double) {
        const double gap = measure(*entries[i].sim);
        entries[i].gap = std::max(entries[i].gap, gap);
        entries[i].gap_sum += gap;
        return true;
      });
  for (std::size_t i = 0; i < entries.size(); ++i)
    print_run(label, entries[i], times[i],
              has_reference ? median_turn_ratio(times[i], times[reference]) : 0.0, steps,
              has_reference ? "Bullet float" : "(no peer)");
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
