// OpenMP regions that cost nothing when they run on one thread.
//
// A `#pragma omp parallel` whose `if` clause is false still makes a team of one, and libgomp
// allocates and frees that team every time: the six regions of a step were 60% of the
// instructions of a one-body step (callgrind), and made every small scene pay for threads it does
// not use. These helpers call the work directly instead; the worksharing inside a region (omp for,
// single, barrier) is then orphaned and runs on the calling thread, with the same iteration order
// as one thread of a team.
//
// Each region a team runs is also timed for the step's statistics (StepStats::parallel_time and
// idle_time): its wall time, and how long each thread waited at its end for the slowest, which is
// what bench_threads needs to tell serial sections from imbalance. Only the thread that steps
// sets a clock; a lone thread reads none.
#pragma once

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <utility>

namespace tumble {

// Where the regions started by this thread add their times (none unless a step set it).
struct RegionClock {
  double region_seconds = 0;       // wall time inside team regions
  double idle_thread_seconds = 0;  // summed over threads: done, waiting for the team's slowest
};
inline thread_local RegionClock* t_region_clock = nullptr;

// Sets this thread's clock for a scope (a step), restoring the one before: a step may run inside
// another's callback only through a new world, which keeps its own.
class RegionClockScope {
 public:
  explicit RegionClockScope(RegionClock* clock) : before_(std::exchange(t_region_clock, clock)) {}
  ~RegionClockScope() { t_region_clock = before_; }
  RegionClockScope(const RegionClockScope&) = delete;
  RegionClockScope& operator=(const RegionClockScope&) = delete;

 private:
  RegionClock* before_;
};

namespace detail {

// The clock of one region: each thread stamps when its share is done.
class RegionTimer {
 public:
  static constexpr int kMostThreads = 256;
  explicit RegionTimer(RegionClock* clock) : clock_(clock) {
    if (clock_ != nullptr) start_ = std::chrono::steady_clock::now();
  }
  void thread_done() {
    if (clock_ == nullptr) return;
    const int t = omp_get_thread_num();
    if (t < kMostThreads) done_[t] = std::chrono::steady_clock::now();
  }
  void region_done() {
    if (clock_ == nullptr) return;
    const auto end = std::chrono::steady_clock::now();
    clock_->region_seconds += std::chrono::duration<double>(end - start_).count();
    const int team = std::min(used_threads_, kMostThreads);
    for (int t = 0; t < team; ++t)
      clock_->idle_thread_seconds += std::chrono::duration<double>(end - done_[t]).count();
  }
  void set_team(int threads) { used_threads_ = threads; }

 private:
  RegionClock* clock_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point done_[kMostThreads];
  int used_threads_ = 0;
};

}  // namespace detail

// Whether `items` of a loop, each about `nanoseconds_each` on one thread, are worth a team.
// Under OMP_WAIT_POLICY=passive (our programs' default) a team's threads sleep between regions,
// and waking them costs tens of microseconds, more on a virtual machine whose idle cores halt
// (measured 2026-11-29 on a 2-core one: a region of 20 us of work took 60-200 us on two
// threads). A region pays when its work is several wake-ups: about 50 us on one thread. The
// per-item costs at the call sites are one thread's, measured by a region's time over its items
// in the landed pile of 4000 (bench_threads with a timing probe).
inline constexpr double kRegionWorthNanoseconds = 50'000;
constexpr bool worth_a_team(std::int64_t items, double nanoseconds_each) {
  return static_cast<double>(items) * nanoseconds_each >= kRegionWorthNanoseconds;
}

// Runs `region()` on a team of `threads` when `parallel` and threads > 1, else on this thread.
template <class Region>
void run_region(int threads, bool parallel, Region&& region) {
  if (parallel && threads > 1) {
    detail::RegionTimer timer(t_region_clock);
#pragma omp parallel num_threads(threads)
    {
#pragma omp single nowait
      timer.set_team(omp_get_num_threads());
      region();
      timer.thread_done();
    }
    timer.region_done();
  } else {
    region();
  }
}

// Inside run_region: body(i) for i in [0, n) handed out one at a time over the team, or in order
// on a lone thread. An orphaned dynamic loop outside any team would still ask libgomp for a work
// share, which it allocates.
template <class Body>
void team_for_dynamic(std::int64_t n, Body&& body) {
  if (omp_in_parallel()) {
#pragma omp for schedule(dynamic, 1)
    for (std::int64_t i = 0; i < n; ++i)
      body(i);
  } else {
    for (std::int64_t i = 0; i < n; ++i)
      body(i);
  }
}

// body(i) for i in [0, n): split over a team when `parallel` (statically, or handed out
// `dynamic_chunk` at a time when that is > 0), else in order here.
template <class Body>
void for_indices(int threads, bool parallel, std::int64_t n, Body&& body, int dynamic_chunk = 0) {
  if (parallel && threads > 1) {
    detail::RegionTimer timer(t_region_clock);
#pragma omp parallel num_threads(threads)
    {
#pragma omp single nowait
      timer.set_team(omp_get_num_threads());
      if (dynamic_chunk > 0) {
#pragma omp for schedule(dynamic, dynamic_chunk) nowait
        for (std::int64_t i = 0; i < n; ++i)
          body(i);
      } else {
#pragma omp for schedule(static) nowait
        for (std::int64_t i = 0; i < n; ++i)
          body(i);
      }
      timer.thread_done();
    }
    timer.region_done();
  } else {
    for (std::int64_t i = 0; i < n; ++i)
      body(i);
  }
}

// The bitwise or of body(i) over [0, n), handed out in chunks of `chunk` when `parallel` (or is
// associative and commutative, so the answer does not depend on the split).
template <class Body>
std::uint32_t or_over_indices(int threads, bool parallel, std::int64_t n, int chunk, Body&& body) {
  std::uint32_t result = 0;
  if (parallel && threads > 1) {
    detail::RegionTimer timer(t_region_clock);
#pragma omp parallel num_threads(threads) reduction(| : result)
    {
#pragma omp single nowait
      timer.set_team(omp_get_num_threads());
#pragma omp for schedule(dynamic, chunk) nowait
      for (std::int64_t i = 0; i < n; ++i)
        result |= body(i);
      timer.thread_done();
    }
    timer.region_done();
  } else {
    for (std::int64_t i = 0; i < n; ++i)
      result |= body(i);
  }
  return result;
}

}  // namespace tumble
