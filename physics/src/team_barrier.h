// A barrier for the step's team inside the solver's regions, where a step waits at hundreds of
// them (the soft solve ends every colour of a large island with one, 16 or 17 colours times 24
// sweeps): it spins for a while, then sleeps.
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
#include <chrono>
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
    const Clock::time_point start = Clock::now();
    Clock::time_point now = start;
    const Clock::duration budget = spin_budget;
    for (std::uint32_t spins = 1;; ++spins) {
      if (generation_.load(std::memory_order_acquire) != generation) {
        // The spin was worth it: spin a little longer next time, up to the bound.
        spin_budget = std::min(kLongestSpin, budget + budget / 8 + kShortestSpin);
        return;
      }
      pause();
      // The clock costs tens of pauses' time; read it now and then.
      if (spins % kSpinsPerReading == 0 && (now = Clock::now()) - start >= budget) break;
    }
    while (generation_.load(std::memory_order_acquire) == generation)
      generation_.wait(generation, std::memory_order_acquire);
    // A wait far past any wake-up's delay means a team thread lost its core (a busy machine):
    // spin less, so that waiting leaves the core to it. Shorter ones are the team's own (a colour
    // out of balance, the sleepers' wake-ups), where shrinking would make each wait a sleep and
    // each sleep a late arrival at the next barrier: on 16 cores that spiral took the pile of
    // 4000's solve from 17 ms on one thread to 67 ms (PERFORMANCE.md).
    if (Clock::now() - start > kLostCore) spin_budget = std::max(kShortestSpin, budget / 4);
  }

 private:
  using Clock = std::chrono::steady_clock;
  // How long a thread spins before it sleeps, its own (a thread_local: what its waits found on
  // this machine lately), adapting as glibc's adaptive mutexes do: waits that end within the spin
  // lengthen it a little, to 100 µs at most; a wait of over half a millisecond, a scheduler's
  // slice rather than a wake-up, cuts it to a quarter. Measured by the clock, since a pause lasts
  // from a few to 140 cycles from one processor to the next.
  static constexpr Clock::duration kShortestSpin = std::chrono::microseconds(1);
  static constexpr Clock::duration kLongestSpin = std::chrono::microseconds(100);
  static constexpr Clock::duration kLostCore = std::chrono::microseconds(500);
  static constexpr std::uint32_t kSpinsPerReading = 16;
  static inline thread_local Clock::duration spin_budget = kLongestSpin;
  static void pause() {
#if defined(__x86_64__)
    _mm_pause();
#endif
  }

  alignas(64) std::atomic<std::uint32_t> arrived_{0};
  alignas(64) std::atomic<std::uint32_t> generation_{0};
  int team_ = 1;
};

}  // namespace tumble
