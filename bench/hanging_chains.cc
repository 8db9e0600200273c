// The geometric stiffness's stress matrix (docs/DYNAMICS.md, "Heavy ends: the geometric
// stiffness"): 810 chains hanging from the world, their last link R times heavier and pushed
// sideways at 1 m/s as they are made, each swung SECONDS with the default solver. Links are
// beads (spheres of radius 5 mm, 2 cm or 5 cm, on massless rods: the least inertia a link can
// have) or square bars (1 or 4 cm across), 0.1, 0.2 or 0.5 m apart, 10, 20 or 40 of them; R is 10, 100,
// 300, 1e3, 1e4 or 1e6; dt 1/30, 1/60 or 1/120. Ball joints at the links' ends, or with --rods
// distance joints between the links' centres (a rope of beads). Prints every chain whose worst
// joint gap of any step passed 1e-6 m (a run stops once past 1 m: torn), then how many.
//
// Usage: bench_hanging_chains [SECONDS] [--rods]
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "physics/world.h"

using namespace tumble;

namespace {

double worst_gap(bool beads, double size, double link, int n, double ratio, double dt,
                 double seconds, bool rods) {
  WorldSettings settings;
  settings.solver.sleeping = false;
  World world(settings);
  const Vec3 top(0, 0, 10);
  BodyId last;
  for (int i = 0; i < n; ++i) {
    BodyDef def;
    def.shape = beads ? ShapeDef{SphereDef{size}} : ShapeDef{BoxDef{Vec3(size, size, link / 2)}};
    def.position = top - Vec3(0, 0, link * (i + 0.5));
    def.mass = i == n - 1 ? 0.5 * ratio : 0.5;
    if (i == n - 1) def.linear_velocity = Vec3(1, 0, 0);
    const BodyId body = world.create_body(def).value();
    JointDef joint;
    joint.a = body;
    joint.b = last;
    joint.anchor = top - Vec3(0, 0, link * i);
    if (rods) {
      joint.kind = JointKind::kDistance;
      joint.anchor = def.position;
      joint.anchor_b = i == 0 ? top : Vec3(top - Vec3(0, 0, link * (i - 0.5)));
    }
    if (!world.create_joint(joint)) {
      std::fprintf(stderr, "bench_hanging_chains: a joint was refused\n");
      std::exit(1);
    }
    last = body;
  }
  double worst = 0;
  const int steps = static_cast<int>(seconds / dt + 0.5);
  for (int step = 0; step < steps && worst <= 1; ++step) {
    if (!world.step(dt)) return 1e300;
    worst = std::max(worst, world.last_step().joint_error);
  }
  return worst;
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 10;
  bool rods = false;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--rods") == 0) {
      rods = true;
    } else {
      char* end = nullptr;
      seconds = std::strtod(argv[i], &end);
      if (*end != '\0' || !(seconds > 0 && seconds <= 100)) {
        std::fprintf(stderr, "usage: bench_hanging_chains [SECONDS 0-100] [--rods]\n");
        return 2;
      }
    }
  }
  int over = 0, torn = 0, chains = 0;
  for (const bool beads : {true, false})
    for (const double size : {0.005, 0.02, 0.05})
      for (const double link : {0.1, 0.2, 0.5})
        for (const int n : {10, 20, 40})
          for (const double ratio : {10.0, 100.0, 300.0, 1e3, 1e4, 1e6})
            for (const double rate : {30.0, 60.0, 120.0}) {
              if (!beads && size == 0.05) continue;  // bars 1 and 4 cm across
              const double worst =
                  worst_gap(beads, size, link, n, ratio, 1 / rate, seconds, rods);
              ++chains;
              if (!(worst <= 1e-6)) {
                ++over;
                if (!(worst <= 1)) ++torn;
                std::printf("%s %g m, %g m apart, %d links, 1:%g, dt 1/%g: %.3g m\n",
                            beads ? "beads of radius" : "bars of half width", size, link, n, ratio,
                            rate, worst);
              }
            }
  std::printf("%d of %d chains over 1e-6 m, %d of them torn (over 1 m)\n", over, chains, torn);
}
