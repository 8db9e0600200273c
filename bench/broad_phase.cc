// Broad-phase scaling: time per body for 1k, 10k and 100k boxes at constant density, hash grid
// (1 and 2 threads) and sweep-and-prune, median of 7 runs after a warm-up.
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "broad_phase.h"
#include "timing.h"

using namespace tumble;

using tumble::bench::median;

int main() {
  std::printf("Broad phase scaling, unit-size boxes at 1 box per 8 m^3 (bench/broad_phase.cc)\n");
  std::printf(
      "| bodies | method | threads | pairs | ms (median of 7) | ns per body "
      "|\n|---|---|---|---|---|---|\n");
  for (int n : {1000, 10000, 100000}) {
    // A fixed LCG so that every run and machine sees the same scene.
    std::uint32_t state = 12345;
    auto uniform = [&] {
      state = 1664525u * state + 1013904223u;
      return (state >> 8) / 16777216.0;
    };
    const double side = std::cbrt(8.0 * n);
    std::vector<Aabb> bounds(n);
    std::vector<std::uint8_t> movable(n, 1);
    for (int i = 0; i < n; ++i) {
      const Vec3 c(uniform() * side, uniform() * side, uniform() * side);
      const Vec3 h = Vec3::Constant(0.5 + 0.3 * uniform());
      bounds[i] = {c - h, c + h};
    }
    struct Variant {
      const char* name;
      int threads;
      bool grid;
    };
    for (const Variant v : {Variant{"hash grid", 1, true}, Variant{"hash grid", 2, true},
                            Variant{"sweep and prune", 1, false}}) {
      const BroadPhaseInput input{bounds, movable, v.threads};
      HashGrid grid;
      std::vector<BodyPair> pairs;
      std::vector<double> times;
      for (int run = 0; run < 8; ++run) {
        const auto start = std::chrono::steady_clock::now();
        if (v.grid)
          grid.find_pairs(input, &pairs);
        else
          sweep_and_prune(input, &pairs);
        const double ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        if (run > 0) times.push_back(ms);
      }
      const double ms = median(times);
      std::printf("| %d | %s | %d | %zu | %.3f | %.0f |\n", n, v.name, v.threads, pairs.size(), ms,
                  ms * 1e6 / n);
    }
  }
  return 0;
}
