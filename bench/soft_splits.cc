// How the soft solver's work is split between substeps, sweeps with the spring and relaxing
// sweeps, against what each split costs and what it gets wrong: the measurement its defaults
// (4 substeps x (3 + 3)) stand on, beside `tumble-report --sweeps` (error against run time on the
// report's scenes). Every row is one thread, sleeping off, on the standard scenes:
//   - pile of 1000 (S1), 10 s: median solve and step time over steps 200-600, the largest kinetic
//     energy in the last second and the boxes still faster than 0.1 m/s at the end (settled?);
//   - eight boxes spawned each half inside the last: the fastest any is pushed out (thrown?);
//   - pyramid of 20 (S2), 10 s: the largest move of any box (standing still?).
// The pile's last-second energy is chaotic (which box topples last): compare orders of magnitude.
//
// Usage: bench_soft_splits [SUBSTEPSxSOLVE+RELAX ...] (default: the splits in kDefaultSplits)
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "physics/world.h"
#include "scenes/standard.h"
#include "timing.h"

namespace {

using namespace tumble;

struct Split {
  int substeps = 4, solve = 3, relax = 3;
};

constexpr Split kDefaultSplits[] = {{4, 3, 3}, {4, 2, 2}, {4, 2, 1}, {4, 1, 1}, {4, 1, 3},
                                    {4, 2, 3}, {4, 3, 2}, {3, 2, 2}, {6, 1, 1}, {8, 1, 1}};

bool parse_split(const std::string& text, Split* out) {
  int consumed = 0;
  return std::sscanf(text.c_str(), "%dx%d+%d%n", &out->substeps, &out->solve, &out->relax,
                     &consumed) == 3 &&
         consumed == static_cast<int>(text.size()) && out->substeps >= 1 && out->solve >= 1 &&
         out->relax >= 1 && out->substeps <= 64 && out->solve <= 64 && out->relax <= 64;
}

World make(SceneDef scene, const Split& split) {
  scene.world.threads = 1;
  scene.world.solver.kind = SolverKind::kSoft;
  scene.world.solver.sleeping = false;
  scene.world.solver.substeps = split.substeps;
  scene.world.solver.soft_iterations = split.solve;
  scene.world.solver.relax_iterations = split.relax;
  return make_world(scene).value();
}

template <class Visit>
void each_dynamic(const World& world, Visit visit) {
  for (std::uint32_t slot = 0; slot < world.slot_count(); ++slot)
    if (const BodyView body = world.body(world.id_at(slot)); body && !body.is_static())
      visit(slot, body);
}

double kinetic_energy(const World& world) {
  double sum = 0;
  each_dynamic(world, [&](std::uint32_t, BodyView b) {
    const Vec3 w_body = b.orientation().conjugate() * b.angular_velocity();
    sum += 0.5 * b.mass() * b.linear_velocity().squaredNorm() +
           0.5 * w_body.dot(b.inertia_body() * w_body);
  });
  return sum;
}

using tumble::bench::median;

struct PileRow {
  double solve_ms = 0, step_ms = 0, last_second_energy = 0;
  int fast = 0;
};

PileRow run_pile(const Split& split) {
  const SceneDef scene = pile_scene(1000);
  World world = make(scene, split);
  std::vector<double> solve, total;
  PileRow row;
  for (int i = 0; i < 600; ++i) {
    if (!world.step(scene.dt)) break;
    if (i >= 200) {
      solve.push_back(world.last_step().time.solve * 1e3);
      total.push_back(world.last_step().time.total * 1e3);
    }
    if (i >= 540) row.last_second_energy = std::max(row.last_second_energy, kinetic_energy(world));
  }
  each_dynamic(world,
               [&](std::uint32_t, BodyView b) { row.fast += b.linear_velocity().norm() > 0.1; });
  row.solve_ms = median(solve);
  row.step_ms = median(total);
  return row;
}

// The scene of test Overlap.HalfOverlappingBoxesSeparateGently.
double run_overlap(const Split& split) {
  SceneDef scene = tower_scene(0);
  for (int i = 0; i < 8; ++i) {
    BodyDef box;
    box.shape = BoxDef{Vec3::Constant(0.5)};
    box.mass = 1;
    box.position = Vec3(0.5 * (i % 2), 0.1 * i, 0.5 + 0.5 * i);
    scene.bodies.push_back(box);
  }
  World world = make(scene, split);
  double fastest = 0;
  for (int i = 0; i < 300 && world.step(scene.dt); ++i)
    each_dynamic(world, [&](std::uint32_t, BodyView b) {
      fastest = std::max(fastest, b.linear_velocity().norm());
    });
  return fastest;
}

double run_pyramid(const Split& split) {
  const SceneDef scene = pyramid_scene(20);
  World world = make(scene, split);
  std::vector<Vec3> start(world.slot_count(), Vec3::Zero());
  each_dynamic(world, [&](std::uint32_t slot, BodyView b) { start[slot] = b.position(); });
  for (int i = 0; i < 600 && world.step(scene.dt); ++i) {
  }
  double moved = 0;
  each_dynamic(world, [&](std::uint32_t slot, BodyView b) {
    moved = std::max(moved, (b.position() - start[slot]).norm());
  });
  return moved;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<Split> splits;
  for (int i = 1; i < argc; ++i) {
    Split split;
    if (!parse_split(argv[i], &split)) {
      std::fprintf(stderr,
                   "bench_soft_splits: '%s' is not SUBSTEPSxSOLVE+RELAX (like 4x3+3, each in "
                   "[1, 64])\n",
                   argv[i]);
      return 2;
    }
    splits.push_back(split);
  }
  if (splits.empty()) splits.assign(std::begin(kDefaultSplits), std::end(kDefaultSplits));

  std::printf("%-9s %7s | %9s %8s %13s %5s | %13s | %15s\n", "split", "passes", "solve ms",
              "step ms", "pile KE, J", "fast", "overlap, m/s", "pyramid move, m");
  for (const Split& split : splits) {
    const PileRow pile = run_pile(split);
    const double thrown = run_overlap(split);
    const double moved = run_pyramid(split);
    // Row passes a step: per substep the warm start, the sweeps with the spring, the relaxing
    // sweeps (an upper bound: sweeps stop early once nothing changes).
    const int passes = split.substeps * (1 + split.solve + split.relax);
    std::printf("%dx(%d+%d)    %7d | %9.3f %8.3f %13.4g %5d | %13.2f | %15.4f\n", split.substeps,
                split.solve, split.relax, passes, pile.solve_ms, pile.step_ms,
                pile.last_second_energy, pile.fast, thrown, moved);
    std::fflush(stdout);
  }
  return 0;
}
