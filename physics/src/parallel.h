// OpenMP regions that cost nothing when they run on one thread.
//
// A `#pragma omp parallel` whose `if` clause is false still makes a team of one, and libgomp
// allocates and frees that team every time: the six regions of a step were 60% of the
// instructions of a one-body step (callgrind), and made every small scene pay for threads it does
// not use. These helpers call the work directly instead; the worksharing inside a region (omp for,
// single, barrier) is then orphaned and runs on the calling thread, with the same iteration order
// as one thread of a team.
#pragma once

#include <omp.h>

#include <cstdint>

namespace tumble {

// Runs `region()` on a team of `threads` when `parallel` and threads > 1, else on this thread.
template <class Region>
void run_region(int threads, bool parallel, Region&& region) {
  if (parallel && threads > 1) {
#pragma omp parallel num_threads(threads)
    region();
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
  if (parallel && threads > 1 && dynamic_chunk > 0) {
#pragma omp parallel for schedule(dynamic, dynamic_chunk) num_threads(threads)
    for (std::int64_t i = 0; i < n; ++i)
      body(i);
  } else if (parallel && threads > 1) {
#pragma omp parallel for schedule(static) num_threads(threads)
    for (std::int64_t i = 0; i < n; ++i)
      body(i);
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
#pragma omp parallel for schedule(dynamic, chunk) num_threads(threads) reduction(| : result)
    for (std::int64_t i = 0; i < n; ++i)
      result |= body(i);
  } else {
    for (std::int64_t i = 0; i < n; ++i)
      result |= body(i);
  }
  return result;
}

}  // namespace tumble
