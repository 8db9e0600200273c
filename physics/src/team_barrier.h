// A barrier for the step's team inside the solver's regions, where a step waits at hundreds of
// them (the soft solve ends every colour of a large island with one, 16 or 17 colours times 24
// sweeps): it spins for a few microseconds, then sleeps.
//
// libgomp's own barrier sleeps in a futex at once when OMP_WAIT_POLICY is passive, which our
// programs set so that spinning threads do not starve a busy machine between steps; waking the
// sleepers at every colour cost the landed pile of 4000 19 ms a step on two threads, which then
// took 31 ms to solve against 12.6 on one (PERFORMANCE.md, "The solver's barriers"). Most
// colours end within the spin, so the team goes on without a wake-up; a thread whose wait outlasts
// it sleeps as before, leaving the core to whatever else needs it (yielding instead cost a machine
// with one other busy process twice the step, measured).
//
// Sense-reversing, centralised (Mellor-Crummey and Scott, "Algorithms for scalable
// synchronization on shared-memory multiprocessors", 1991): the last thread to arrive resets the
// count and advances the generation, which the others watch.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace tumble {

class TeamBarrier {
 public:
  // Before the team's first wait, by one thread, with a barrier of the team's own after it (an
  // `omp single`).
  void reset(int team) {
    team_ = team;
    arrived_.store(0, std::memory_order_relaxed);
  }

  void wait() {
    if (team_ <= 1) return;
    const std::uint32_t generation = generation_.load(std::memory_order_acquire);
    if (arrived_.fetch_add(1, std::memory_order_acq_rel) + 1 == static_cast<std::uint32_t>(team_)) {
      arrived_.store(0, std::memory_order_relaxed);
      generation_.fetch_add(1, std::memory_order_release);
      generation_.notify_all();
      return;
    }
    const std::uint32_t limit = spin_limit_.load(std::memory_order_relaxed);
    for (std::uint32_t spins = 0; spins < limit; ++spins) {
      if (generation_.load(std::memory_order_acquire) != generation) {
        // The spin was worth it: spin a little longer next time, up to the bound.
        spin_limit_.store(std::min(kMostSpins, limit + limit / 16 + 1), std::memory_order_relaxed);
        return;
      }
      pause();
    }
    // Still waiting: the team's slowest thread may have lost its core (a busy machine), so sleep
    // until the generation moves (a futex on Linux), and spin less next time.
    spin_limit_.store(std::max(kFewestSpins, limit / 4), std::memory_order_relaxed);
    while (generation_.load(std::memory_order_acquire) == generation)
      generation_.wait(generation, std::memory_order_acquire);
  }

 private:
  // How long a thread spins before it sleeps adapts, as glibc's adaptive mutexes do: waits that
  // end within the spin lengthen it a little (to some tens of µs of pauses at most), waits that
  // outlast it cut it to a quarter. On a quiet machine most colours end within the spin; on one
  // where another busy process takes a core, the team's threads lose theirs in turn, waits
  // outlast the spin, and it shrinks to almost nothing. Measured on the landed piles (two threads
  // against one, OMP_WAIT_POLICY=passive; PERFORMANCE.md): a fixed spin of 1000 pauses 1.61x
  // quiet but 0.54x beside one busy process; no spin 0.92x and 1.12x; this 1.42-1.52x and
  // 0.60-1.01x, where libgomp's barrier gave 0.72-0.92x and 0.71-0.98x.
  static constexpr std::uint32_t kMostSpins = 2000, kFewestSpins = 16;
  static void pause() {
#if defined(__x86_64__)
    _mm_pause();
#endif
  }

  alignas(64) std::atomic<std::uint32_t> arrived_{0};
  alignas(64) std::atomic<std::uint32_t> generation_{0};
  alignas(64) std::atomic<std::uint32_t> spin_limit_{kMostSpins};
  int team_ = 1;
};

}  // namespace tumble
