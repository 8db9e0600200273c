// What a world pays to create hull bodies: a field of rocks made from one set of points (as a scene
// of many copies of one rock file gives) against the same number of rocks of distinct points (no
// two alike), each made by one `create_bodies` batch. Per body: the creation time (median of the
// rounds) and the heap the live world holds. The distinct rocks are the control in
// the same run: each must be built on its own, so their ratio to the alike ones is what sharing
// buys.
//
// Usage: bench_hull_creation [BODIES [ROUNDS]]   (defaults 1000, 5; one thread)
#include <malloc.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "physics/world.h"
#include "timing.h"

namespace {

using tumble::BodyDef;
using tumble::HullDef;
using tumble::Vec3;
using tumble::bench::median;

// A rock: `count` points on a lumpy ellipsoid (every point a vertex of the hull or near one).
std::vector<Vec3> rock(std::mt19937_64& random, int count) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0), lump(0.85, 1.0);
  std::vector<Vec3> points;
  while (static_cast<int>(points.size()) < count) {
    const Vec3 d(unit(random), unit(random), unit(random));
    if (d.squaredNorm() < 1e-3 || d.squaredNorm() > 1) continue;
    points.push_back(d.normalized().cwiseProduct(Vec3(0.4, 0.3, 0.2)) * lump(random));
  }
  return points;
}

// Heap bytes in use (glibc's count, mmapped blocks included): unlike the resident size, freed
// memory reused by the next round does not hide what this one holds.
double heap_kb() {
  const struct mallinfo2 info = mallinfo2();
  return static_cast<double>(info.uordblks + info.hblkhd) / 1024;
}

struct Result {
  double us_per_body = 0;
  double kb_per_body = 0;
};

Result create(const std::vector<std::vector<Vec3>>& rocks, int bodies) {
  std::vector<BodyDef> defs(bodies);
  for (int i = 0; i < bodies; ++i) {
    defs[i].shape = HullDef{rocks[i % rocks.size()]};
    defs[i].position = Vec3(1.0 * (i % 100), 1.0 * (i / 100), 1.0);
  }
  const double before_kb = heap_kb();
  tumble::World world;
  const auto start = std::chrono::steady_clock::now();
  auto ids = world.create_bodies(defs);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!ids) {
    std::fprintf(stderr, "bench_hull_creation: %s\n", ids.status().message().c_str());
    std::exit(1);
  }
  return {1e6 * seconds / bodies, (heap_kb() - before_kb) / bodies};
}

}  // namespace

int main(int argc, char** argv) {
  const int bodies = argc > 1 ? std::atoi(argv[1]) : 1000;
  const int rounds = argc > 2 ? std::atoi(argv[2]) : 5;
  if (bodies < 1 || bodies > 100000 || rounds < 1 || rounds > 100) {
    std::fprintf(stderr, "usage: bench_hull_creation [BODIES 1..100000 [ROUNDS 1..100]]\n");
    return 2;
  }
  std::printf(
      "%d hull bodies created in one batch, %d rounds, one thread: median us and KB a body\n",
      bodies, rounds);
  std::printf("%-8s %12s %12s %12s %12s %10s\n", "points", "alike us", "distinct us", "alike KB",
              "distinct KB", "ratio");
  for (const int points : {64, 1024}) {
    std::mt19937_64 random(20261205);
    const std::vector<std::vector<Vec3>> one{rock(random, points)};
    std::vector<std::vector<Vec3>> distinct;
    for (int i = 0; i < bodies; ++i)
      distinct.push_back(rock(random, points));
    std::vector<double> alike_us, distinct_us, alike_kb, distinct_kb;
    for (int round = 0; round < rounds; ++round) {
      const Result a = create(one, bodies);
      const Result d = create(distinct, bodies);
      alike_us.push_back(a.us_per_body);
      distinct_us.push_back(d.us_per_body);
      alike_kb.push_back(a.kb_per_body);
      distinct_kb.push_back(d.kb_per_body);
    }
    std::printf("%-8d %12.2f %12.2f %12.2f %12.2f %9.3fx\n", points, median(alike_us),
                median(distinct_us), median(alike_kb), median(distinct_kb),
                median(alike_us) / median(distinct_us));
  }
  return 0;
}
