// What the benchmarks share to time their runs: the median of a list of times, a stopwatch in
// milliseconds, and stepping several runs by turns so that a ratio of their times holds on a
// shared machine whose speed moves by half within a minute.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <limits>
#include <span>
#include <vector>

namespace tumble::bench {

// The middle value (the upper of the two middle ones of an even count); 0 for none.
inline double median(std::vector<double> values) {
  if (values.empty()) return 0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

inline double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// Steps per turn: long enough that a turn's untimed first step is a small share, short enough
// that every run meets the machine's changing speed many times.
constexpr long kTurnSteps = 20;

// One run's times as take_turns kept them.
struct TurnTimes {
  std::vector<double> step_ms;  // every timed step, in order
  std::vector<double> turn_ms;  // each turn's median
  long steps = 0;               // steps taken (timed or not)
  bool stopped = false;         // it took no more turns (set it to leave a run out)
};

// Steps `steps` steps of every run, the runs taking turns of kTurnSteps steps, so that each meets
// the shared machine at the same speeds: run one after the other, two engines' 5 s ran up to a
// quarter apart in speed, which went straight into their ratio. A turn's first step finds the
// caches full of the other runs' data and is not timed (taking turns a step at a time slowed
// Bullet's steps by half and ours by less: not the step either engine takes alone).
// `step(i, k)`: run i's step k; false when the engine cannot go on (the step not counted, the run
// stopped). `after(i, k, ms)`: untimed work after it (sampling its error), given the step's time
// in ms, or NaN for a turn's first step; false stops the run (a time limit).
template <class Step, class After>
void take_turns(std::span<TurnTimes> runs, long steps, Step step, After after) {
  std::vector<double> turn;
  for (long first = 0; first < steps; first += kTurnSteps) {
    const long end = std::min(steps, first + kTurnSteps);
    for (std::size_t i = 0; i < runs.size(); ++i) {
      TurnTimes& run = runs[i];
      turn.clear();
      for (long k = first; k < end && !run.stopped; ++k) {
        const auto start = std::chrono::steady_clock::now();
        if (!step(i, k)) {
          run.stopped = true;
          break;
        }
        const double ms = ms_since(start);
        ++run.steps;
        const bool timed = k > first;
        if (timed) turn.push_back(ms);
        if (!after(i, k, timed ? ms : std::numeric_limits<double>::quiet_NaN())) run.stopped = true;
      }
      if (turn.empty()) continue;
      run.step_ms.insert(run.step_ms.end(), turn.begin(), turn.end());
      run.turn_ms.push_back(median(turn));
    }
  }
}

// A run's time over the reference's, turn by turn (each turn's median over the other's in the
// same turn), and the median of those ratios: a ratio the machine's changing speed moves far less
// than a ratio of two runs' medians. 0 where they share no turn.
inline double median_turn_ratio(const TurnTimes& run, const TurnTimes& reference) {
  std::vector<double> ratios;
  for (std::size_t k = 0; k < std::min(run.turn_ms.size(), reference.turn_ms.size()); ++k)
    if (reference.turn_ms[k] > 0) ratios.push_back(run.turn_ms[k] / reference.turn_ms[k]);
  return median(ratios);
}

}  // namespace tumble::bench
