// The same stretch of a scene stepped again and again from one saved state, for comparing two
// builds of the engine with less noise than whole runs give: a whole run's time moves with its
// chaotic first seconds (where a pile lands, which islands are exact) and with everything else
// the shared machine does meanwhile; here every round steps exactly the same work (a restored
// world steps on bit for bit, World::save_state), and the rounds of two builds can be alternated.
//
// Usage: bench_replay SCENE [FROM [STEPS [ROUNDS [THREADS]]]]
//   SCENE    a standard scene (standard.h): pile:16000, pyramid:20, ...
//   FROM     steps taken once before the state is saved (default 120)
//   STEPS    steps per round from that state (default 10)
//   ROUNDS   rounds (default 5)
//   THREADS  step threads (default 1)
// TUMBLE_SOLVER=exact|pgs|soft|auto in the environment replaces the scene's solver, and
// TUMBLE_SUBSTEPS=N (1 to 32) its substeps, TUMBLE_JOINT_PASSES=N (0 to 32) its joint position
// passes, and TUMBLE_JOINT_FRICTION=F (N m, 0 or more) every joint's friction (bench_joints times
// the ragdolls with 0: no peer maps it).
// Sleeping is off, so the whole scene is awake. Each round restores the state, takes two untimed
// steps (the restored world's buffers warm up) and times STEPS more. Prints the mean time per step
// of each stage per round, then each stage's minimum and median over the rounds, and the state's
// hash after a round (the same in every round, and in two builds that change no bit); after the
// first round, what a step of it solved (manifolds, contact points, sweeps summed over islands and
// substeps), which says whether a change of time is a change of work.
//
// Comparing builds A and B: run them alternately, e.g.
//   for r in 1 2 3; do A/bench_replay pile:16000; B/bench_replay pile:16000; done
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include "physics/world.h"
#include "scene_runner.h"  // tests/: state_hash
#include "scenes/standard.h"
#include "timing.h"

namespace {

using namespace tumble;

struct Times {
  double broad = 0, narrow = 0, prepare = 0, solve = 0, total = 0;
};

// What one step of the round solved (the same every round): its size and how many sweeps.
struct Work {
  std::uint64_t points = 0, manifolds = 0, sweeps = 0, islands = 0, exact_islands = 0, pivots = 0;
  std::uint64_t coloured_islands = 0, colours = 0, overflow_manifolds = 0;
};

int whole_argument(int argc, char** argv, int index, int fallback, int least, int most) {
  if (argc <= index) return fallback;
  char* end = nullptr;
  const long value = std::strtol(argv[index], &end, 10);
  if (*end != '\0' || value < least || value > most) {
    std::fprintf(stderr,
                 "bench_replay: argument %d (\"%s\") must be a whole number from %d to %d\n", index,
                 argv[index], least, most);
    std::exit(2);
  }
  return static_cast<int>(value);
}

using tumble::bench::median;

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_replay SCENE [FROM [STEPS [ROUNDS [THREADS]]]]\n");
    return 2;
  }
  const int from = whole_argument(argc, argv, 2, 120, 0, 100000);
  const int steps = whole_argument(argc, argv, 3, 10, 1, 100000);
  const int rounds = whole_argument(argc, argv, 4, 5, 1, 1000);
  const int threads = whole_argument(argc, argv, 5, 1, 1, 256);
  Result<SceneDef> scene = standard_scene(argv[1]);
  if (!scene.ok()) {
    std::fprintf(stderr, "bench_replay: %s\n", scene.status().message().c_str());
    return 2;
  }
  scene.value().world.threads = threads;
  if (const char* solver = std::getenv("TUMBLE_SOLVER")) {
    const std::optional<SolverKind> kind = solver_from_name(solver);
    if (!kind) {
      std::fprintf(stderr, "bench_replay: TUMBLE_SOLVER=%s is no solver (exact, pgs, soft, auto)\n",
                   solver);
      return 2;
    }
    scene.value().world.solver.kind = *kind;
  }
  if (const char* substeps = std::getenv("TUMBLE_SUBSTEPS")) {
    const int count = std::atoi(substeps);
    if (count < 1 || count > 32) {
      std::fprintf(stderr, "bench_replay: TUMBLE_SUBSTEPS=%s is not 1 to 32\n", substeps);
      return 2;
    }
    scene.value().world.solver.substeps = count;
  }
  if (const char* passes = std::getenv("TUMBLE_JOINT_PASSES")) {
    char* end = nullptr;
    const long count = std::strtol(passes, &end, 10);
    if (end == passes || *end != '\0' || count < 0 || count > 32) {
      std::fprintf(stderr, "bench_replay: TUMBLE_JOINT_PASSES=%s is not 0 to 32\n", passes);
      return 2;
    }
    scene.value().world.solver.joint_position_passes = static_cast<int>(count);
  }
  if (const char* friction = std::getenv("TUMBLE_JOINT_FRICTION")) {
    char* end = nullptr;
    const double value = std::strtod(friction, &end);
    if (*end != '\0' || !(value >= 0) || !std::isfinite(value)) {
      std::fprintf(stderr, "bench_replay: TUMBLE_JOINT_FRICTION=%s is not a force of 0 or more\n",
                   friction);
      return 2;
    }
    for (SceneJoint& joint : scene.value().joints)
      joint.def.friction = value;
  }
  scene.value().world.solver.sleeping = false;
  const double dt = scene.value().dt;
  Result<World> made = make_world(scene.value());
  if (!made.ok()) {
    std::fprintf(stderr, "bench_replay: %s\n", made.status().message().c_str());
    return 2;
  }
  for (int i = 0; i < from; ++i)
    (void)made.value().step(dt);
  const std::string saved = made.value().save_state();
  const WorldSettings settings = made.value().settings();

  std::printf("%s from step %d, %d steps a round, %d thread(s), sleeping off: ms per step\n",
              argv[1], from, steps, threads);
  std::printf("round   broad  narrow prepare   solve   total  state hash\n");
  std::vector<Times> per_round;
  for (int round = 0; round < rounds; ++round) {
    World world = World::from_state(settings, saved).value();
    // A restored world has not sized its step buffers yet: its first steps allocate and fault
    // in pages that a running world's steps reuse (the pair records are two buffers, swapped each
    // step, so it takes two), so they are stepped but not timed.
    for (int warm = 0; warm < 2; ++warm)
      (void)world.step(dt);
    Times sum;
    Work work;
    for (int i = 0; i < steps; ++i) {
      (void)world.step(dt);
      work.points += world.last_step().contact_points;
      work.manifolds += world.last_step().manifolds;
      work.sweeps += world.last_step().velocity_iterations;
      work.islands += world.last_step().islands;
      work.exact_islands += world.last_step().exact_islands;
      work.pivots += world.last_step().lemke_pivots;
      work.coloured_islands += world.last_step().coloured_islands;
      work.colours += world.last_step().colours;
      work.overflow_manifolds += world.last_step().overflow_manifolds;
      const StageTimes& t = world.last_step().time;
      sum.broad += t.broad_phase;
      sum.narrow += t.narrow_phase;
      sum.prepare += t.prepare;
      sum.solve += t.solve;
      sum.total += t.total;
    }
    const double scale = 1e3 / steps;
    const Times mean{sum.broad * scale, sum.narrow * scale, sum.prepare * scale, sum.solve * scale,
                     sum.total * scale};
    per_round.push_back(mean);
    std::printf("%5d %7.3f %7.3f %7.3f %7.3f %7.3f  %016llx\n", round + 1, mean.broad, mean.narrow,
                mean.prepare, mean.solve, mean.total,
                static_cast<unsigned long long>(tumble::testing::state_hash(world)));
    if (round == 0)
      std::printf(
          "      a step: %.0f manifolds, %.0f contact points, %.1f sweeps (velocity "
          "iterations summed over islands and substeps); %.0f islands, %.0f of them exact, "
          "%.0f Lemke pivots;\n"
          "      %.1f islands coloured for the team with %.1f colours, %.1f manifolds in their "
          "serial overflow\n",
          double(work.manifolds) / steps, double(work.points) / steps, double(work.sweeps) / steps,
          double(work.islands) / steps, double(work.exact_islands) / steps,
          double(work.pivots) / steps, double(work.coloured_islands) / steps,
          double(work.colours) / steps, double(work.overflow_manifolds) / steps);
  }
  const auto stage = [&](double Times::*field) {
    std::vector<double> values;
    for (const Times& t : per_round)
      values.push_back(t.*field);
    return values;
  };
  for (const char* label : {"min", "median"}) {
    const bool is_min = label[1] == 'i';
    const auto pick = [&](double Times::*field) {
      const std::vector<double> values = stage(field);
      return is_min ? *std::min_element(values.begin(), values.end()) : median(values);
    };
    std::printf("%-6s%7.3f %7.3f %7.3f %7.3f %7.3f\n", label, pick(&Times::broad),
                pick(&Times::narrow), pick(&Times::prepare), pick(&Times::solve),
                pick(&Times::total));
  }
  return 0;
}
