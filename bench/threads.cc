// What threads buy each stage of the step, and what a machine with more cores would see.
//
// One stretch of a scene is stepped from a saved state (as bench_replay does) on 1, 2, 4 … threads,
// the thread counts alternated within each round so that a noisy minute hits them all. For every
// thread count and stage: the time, the speedup over one thread, the efficiency (speedup over
// threads), the serial time (the stage's time outside team regions, StepStats::parallel_time) and
// the imbalance (the share of the team's thread-time spent waiting at a region's end for its
// slowest thread, StepStats::idle_time).
//
// Amdahl's law then predicts larger machines from the measured rows: with serial time s and the
// one-thread time T1 of a stage, P threads take s + (T1 - s) / P at best ("Amdahl"); the "kept"
// row divides that parallel part by the efficiency the regions themselves kept on the largest team
// measured, e = (T1 - s) / (T x region time), which counts what happens inside them (the barriers
// between colours, imbalance, memory shared by the cores) and so is optimistic only in assuming
// that e does not fall further with more threads. On a 2-core machine this is how the 16-core
// figure is estimated; on a many-core machine the predicted and measured rows can be read side by
// side.
//
// Usage: bench_threads [--from N] [--steps N] [--rounds N] [--threads 1,2,4] [--predict 8,16]
//                      [SCENE ...]   (default: pile:4000, from step 120, 10 steps, 5 rounds,
//                                     threads 1, 2, 4 … up to the machine's, predict 4, 8, 16)
// Sleeping is off. The state's hash after each round must be the same for every thread count;
// the program says so, and exits 1 when it is not.
#include <omp.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "physics/world.h"
#include "scene_runner.h"  // tests/: state_hash
#include "scenes/standard.h"
#include "timing.h"

namespace {

using namespace tumble;

constexpr int kStages = 6;
const char* const kStageNames[kStages] = {"broad", "narrow", "prepare", "solve", "other", "total"};

// A stage's mean ms per step over one round: its time, the part in team regions, the team's
// waiting thread-ms.
struct StageSample {
  double time = 0, parallel = 0, idle = 0;
};
using RoundSample = std::array<StageSample, kStages>;

std::array<double, kStages> split(const StageTimes& t) {
  const double other = t.total - t.broad_phase - t.narrow_phase - t.prepare - t.solve;
  return {t.broad_phase, t.narrow_phase, t.prepare, t.solve, other, t.total};
}

using tumble::bench::median;

std::vector<int> number_list(const std::string& text, const char* flag) {
  std::vector<int> numbers;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    char* end = nullptr;
    const long value = std::strtol(item.c_str(), &end, 10);
    if (item.empty() || *end != '\0' || value < 1 || value > 1024) {
      std::fprintf(stderr, "bench_threads: %s takes whole numbers from 1 to 1024, got \"%s\"\n",
                   flag, item.c_str());
      std::exit(2);
    }
    numbers.push_back(static_cast<int>(value));
  }
  return numbers;
}

int whole(const char* text, const char* flag, int least, int most) {
  char* end = nullptr;
  const long value = std::strtol(text, &end, 10);
  if (*end != '\0' || value < least || value > most) {
    std::fprintf(stderr, "bench_threads: %s must be a whole number from %d to %d, got \"%s\"\n",
                 flag, least, most, text);
    std::exit(2);
  }
  return static_cast<int>(value);
}

// One round on `threads`: mean ms per step of each stage; the state's hash after it.
RoundSample run_round(const WorldSettings& base, const std::string& saved, double dt, int steps,
                      int threads, std::uint64_t* hash) {
  WorldSettings settings = base;
  settings.threads = threads;
  World world = World::from_state(settings, saved).value();
  for (int warm = 0; warm < 2; ++warm)  // a restored world sizes its buffers in its first steps
    (void)world.step(dt);
  RoundSample sample{};
  for (int i = 0; i < steps; ++i) {
    (void)world.step(dt);
    const StepStats& stats = world.last_step();
    const auto time = split(stats.time), parallel = split(stats.parallel_time),
               idle = split(stats.idle_time);
    for (int s = 0; s < kStages; ++s) {
      sample[s].time += 1e3 * time[s] / steps;
      sample[s].parallel += 1e3 * parallel[s] / steps;
      sample[s].idle += 1e3 * idle[s] / steps;
    }
  }
  *hash = tumble::testing::state_hash(world);
  return sample;
}

bool run_scene(const std::string& name, int from, int steps, int rounds,
               const std::vector<int>& thread_counts, const std::vector<int>& predict) {
  Result<SceneDef> scene = standard_scene(name);
  if (!scene.ok()) {
    std::fprintf(stderr, "bench_threads: %s\n", scene.status().message().c_str());
    std::exit(2);
  }
  scene.value().world.solver.sleeping = false;
  scene.value().world.threads = 1;
  const double dt = scene.value().dt;
  World world = make_world(scene.value()).value();
  for (int i = 0; i < from; ++i)
    (void)world.step(dt);
  const std::string saved = world.save_state();
  const WorldSettings settings = world.settings();

  // samples[t][round]
  std::map<int, std::vector<RoundSample>> samples;
  std::map<int, std::uint64_t> hashes;
  bool same_bits = true;
  for (int round = 0; round < rounds; ++round) {
    for (int threads : thread_counts) {
      std::uint64_t hash = 0;
      samples[threads].push_back(run_round(settings, saved, dt, steps, threads, &hash));
      if (hashes.count(threads) == 0) hashes[threads] = hash;
      same_bits = same_bits && hash == hashes.begin()->second && hash == hashes[threads];
    }
  }
  // Medians over the rounds, stage by stage.
  const auto med = [&](int threads, int stage, double StageSample::*field) {
    std::vector<double> values;
    for (const RoundSample& r : samples[threads])
      values.push_back(r[stage].*field);
    return median(values);
  };
  const int one = thread_counts.front();
  // A stage on a team, against its one-thread time: the time outside regions (serial), the
  // regions' own efficiency (their one-thread work over the team's thread-time in them) and the
  // share of that thread-time spent waiting at their ends.
  struct Split {
    double serial = 0, efficiency = 1, waiting = 0;
  };
  const auto split_stage = [&](int threads, int stage) {
    Split split;
    const double region = med(threads, stage, &StageSample::parallel);
    split.serial = std::max(0.0, med(threads, stage, &StageSample::time) - region);
    const double work = std::max(0.0, med(1, stage, &StageSample::time) - split.serial);
    if (region > 0) {
      split.efficiency = std::min(1.0, work / (threads * region));
      split.waiting = med(threads, stage, &StageSample::idle) / (threads * region);
    }
    return split;
  };
  std::printf(
      "\n%s from step %d, %d steps a round, %d rounds (medians), sleeping off; "
      "the machine has %u hardware threads\n",
      name.c_str(), from, steps, rounds, std::thread::hardware_concurrency());
  std::printf("state after a round: %s for every thread count (%016llx)\n",
              same_bits ? "the same bits" : "DIFFERENT BITS",
              static_cast<unsigned long long>(hashes.begin()->second));
  std::printf("ms per step by stage (speedup over %d thread%s, efficiency)\n", one,
              one == 1 ? "" : "s");
  std::printf("%7s", "threads");
  for (const char* stage : kStageNames)
    std::printf(" %22s", stage);
  std::printf("\n");
  for (int threads : thread_counts) {
    std::printf("%7d", threads);
    for (int s = 0; s < kStages; ++s) {
      const double ms = med(threads, s, &StageSample::time);
      const double speedup = med(one, s, &StageSample::time) / ms;
      std::printf(" %8.3f (%5.2fx %4.0f%%)", ms, speedup, 100 * speedup * one / threads);
    }
    std::printf("\n");
  }
  // Where the time of a team goes, stage by stage.
  for (int threads : thread_counts) {
    if (threads == 1 || one != 1) continue;
    std::printf("%7d threads: serial ms / regions' efficiency / team waiting at regions' ends\n",
                threads);
    std::printf("%7s", "");
    for (int s = 0; s < kStages; ++s) {
      const Split split = split_stage(threads, s);
      std::printf(" %7.3f %5.0f%% %5.1f%% ", split.serial, 100 * split.efficiency,
                  100 * split.waiting);
    }
    std::printf("\n");
  }

  // Amdahl from the largest team measured.
  const int largest = *std::max_element(thread_counts.begin(), thread_counts.end());
  if (largest == 1 || one != 1 || predict.empty()) return same_bits;
  std::printf(
      "predicted from the %d-thread row (Amdahl: serial s + (T1 - s) / P; \"kept\": the "
      "parallel part at the efficiency the regions kept on %d threads)\n",
      largest, largest);
  for (int p : predict) {
    for (int kept = 0; kept < 2; ++kept) {
      std::printf("%7d", p);
      for (int s = 0; s < kStages; ++s) {
        const double t1 = med(1, s, &StageSample::time);
        const Split split = split_stage(largest, s);
        const double work = std::max(0.0, t1 - split.serial);
        const double ms = split.serial + work / p / (kept ? std::max(0.05, split.efficiency) : 1.0);
        std::printf(" %8.3f (%5.2fx %4.0f%%)", ms, t1 / ms, 100 * t1 / ms / p);
      }
      std::printf("  %s\n",
                  kept ? "predicted, regions kept their efficiency" : "predicted, Amdahl");
    }
  }
  return same_bits;
}

}  // namespace

int main(int argc, char** argv) {
  int from = 120, steps = 10, rounds = 5;
  std::vector<int> thread_counts, predict = {4, 8, 16};
  std::vector<std::string> scenes;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--from" && has_value) {
      from = whole(argv[++i], "--from", 0, 100000);
    } else if (arg == "--steps" && has_value) {
      steps = whole(argv[++i], "--steps", 1, 100000);
    } else if (arg == "--rounds" && has_value) {
      rounds = whole(argv[++i], "--rounds", 1, 1000);
    } else if (arg == "--threads" && has_value) {
      thread_counts = number_list(argv[++i], "--threads");
    } else if (arg == "--predict" && has_value) {
      predict = number_list(argv[++i], "--predict");
    } else if (!arg.empty() && arg[0] != '-') {
      scenes.push_back(arg);
    } else {
      std::fprintf(stderr,
                   "usage: bench_threads [--from N] [--steps N] [--rounds N] [--threads 1,2,4] "
                   "[--predict 8,16] [SCENE ...]\n");
      return 2;
    }
  }
  if (scenes.empty()) scenes = {"pile:4000"};
  if (thread_counts.empty()) {
    const int machine = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
    for (int t = 1; t < machine; t *= 2)
      thread_counts.push_back(t);
    thread_counts.push_back(machine);
  }
  std::sort(thread_counts.begin(), thread_counts.end());
  thread_counts.erase(std::unique(thread_counts.begin(), thread_counts.end()), thread_counts.end());
  bool same_bits = true;
  for (const std::string& scene : scenes)
    same_bits = run_scene(scene, from, steps, rounds, thread_counts, predict) && same_bits;
  return same_bits ? 0 : 1;
}
