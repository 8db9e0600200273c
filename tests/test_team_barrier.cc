// The solver's team barrier (physics/src/team_barrier.h): no thread leaves a phase before every
// thread has finished it, over many phases and however long the threads take.
#include <gtest/gtest.h>
#include <omp.h>

#include <atomic>
#include <vector>

#include "team_barrier.h"

namespace tumble::testing {
namespace {

// Each thread adds to the phase's counter, waits, and reads it: it must hold the whole team's
// additions, and not yet any of the next phase's (a second wait separates the phases).
TEST(TeamBarrier, NoThreadLeavesAPhaseBeforeEveryThreadFinishedIt) {
  constexpr int kPhases = 2000;
  for (int team : {1, 2, 4}) {
    SCOPED_TRACE(std::to_string(team) + " threads");
    TeamBarrier barrier;
    std::vector<std::atomic<int>> arrived(kPhases);
    std::atomic<int> wrong{0}, threads_seen{0};
    [[maybe_unused]] volatile int sink = 0;
#pragma omp parallel num_threads(team)
    {
#pragma omp single
      {
        barrier.reset(omp_get_num_threads());
        threads_seen = omp_get_num_threads();
      }
      for (int phase = 0; phase < kPhases; ++phase) {
        // Uneven work, so that some threads wait within their spin, some long enough to sleep
        // (past the 100 µs spin) and some past the half millisecond that shortens it.
        const int turn = phase + omp_get_thread_num();
        const int work = turn % 97 == 0   ? 2000000
                         : turn % 31 == 0 ? 300000
                         : turn % 7 == 0  ? 20000
                                          : 0;
        for (int k = 0; k < work; ++k)
          sink = k;
        arrived[phase].fetch_add(1);
        barrier.wait();
        if (arrived[phase].load() != omp_get_num_threads()) wrong.fetch_add(1);
        barrier.wait();
      }
    }
    EXPECT_EQ(threads_seen.load(), team);
    EXPECT_EQ(wrong.load(), 0);
    for (int phase = 0; phase < kPhases; ++phase)
      ASSERT_EQ(arrived[phase].load(), threads_seen.load()) << "phase " << phase;
  }
}

}  // namespace
}  // namespace tumble::testing
