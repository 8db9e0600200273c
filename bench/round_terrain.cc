// Balls and capsules thrown onto the standard rolling hills (terrain:N's, whose cells turn by
// about 1.4°, so that every edge is too gentle to be active), as a heightfield and as the same
// triangles as a mesh: the median time a step over the rounds, and how far any body sank into
// the surface (vertically, at its core's lowest end, less its radius: a bound on the depth along
// the normal), sampled after every step, untimed. What the gentle edges cost round bodies and
// what they hold (docs/COLLISION.md, "Heightfields"). With a small RADIUS (0.05 m) the bodies are
// fast for their size (they move more than 3/4 of their radius a step), and continuous collision
// sweeps every one touching the hills each step (docs/DYNAMICS.md, "Continuous collision").
//
// Usage: bench_round_terrain [BODIES [ROUNDS [RADIUS]]]   (defaults 200, 3, 0.25 m: a ball's
// radius; a capsule's is 0.6 of it and its core 2.4 of it long; one thread, 10 s at 60 Hz)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include "physics/triangle_mesh.h"
#include "physics/world.h"
#include "scenes/standard.h"

namespace tumble {
namespace {

struct Run {
  double ms_per_step = 0;
  double deepest = 0;  // m
};

Run run(const BodyDef& ground, const HeightField& hills, bool capsules, int bodies, double size) {
  WorldSettings settings;
  settings.threads = 1;
  World world(settings);
  (void)world.create_body(ground).value();
  std::mt19937 random(7);
  std::uniform_real_distribution<double> across(-20, 20), sideways(-3, 3);
  std::vector<BodyId> ids;
  for (int i = 0; i < bodies; ++i) {
    BodyDef body;
    body.mass = 1;
    body.shape =
        capsules ? ShapeDef{CapsuleDef{0.6 * size, 1.2 * size}} : ShapeDef{SphereDef{size}};
    body.position = Vec3(across(random), across(random), 2 + 0.02 * i);
    body.linear_velocity = Vec3(sideways(random), sideways(random), -5);
    body.orientation = Quat(Eigen::AngleAxisd(
        across(random), Vec3(sideways(random), sideways(random), 1).normalized()));
    ids.push_back(world.create_body(body).value());
  }
  const Pose pose{ground.position, ground.orientation};
  const double radius = capsules ? 0.6 * size : size;
  Run out;
  double seconds = 0;
  const int steps = 600;
  for (int k = 0; k < steps; ++k) {
    const auto start = std::chrono::steady_clock::now();
    (void)world.step(1.0 / 60);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    for (const BodyId id : ids) {
      const BodyView body = world.body(id);
      for (const double end : {-1.0, 1.0}) {
        const Vec3 core = pose.inverse_transform(
            body.position() + body.orientation() * Vec3(0, 0, capsules ? 1.2 * size * end : 0.0));
        // Bodies that rolled off the hills' edge fall past them: not sinking.
        if (std::abs(core.x()) > 28 || std::abs(core.y()) > 28) continue;
        out.deepest = std::max(out.deepest, hills.height_at(core.x(), core.y()) - core.z() + radius);
      }
    }
  }
  out.ms_per_step = 1e3 * seconds / steps;
  return out;
}

}  // namespace
}  // namespace tumble

int main(int argc, char** argv) {
  using namespace tumble;
  const int bodies = argc > 1 ? std::atoi(argv[1]) : 200;
  const int rounds = argc > 2 ? std::atoi(argv[2]) : 3;
  const double size = argc > 3 ? std::atof(argv[3]) : 0.25;
  if (bodies < 1 || bodies > 10000 || rounds < 1 || rounds > 100 || !(size >= 0.01 && size <= 1)) {
    std::fprintf(
        stderr,
        "usage: bench_round_terrain [BODIES 1..10000 [ROUNDS 1..100 [RADIUS 0.01..1 m]]]\n");
    return 2;
  }
  const SceneDef scene = terrain_pile_scene(1000);
  const BodyDef& field_ground = scene.bodies.front();
  const HeightField hills =
      HeightField::create(std::get<HeightFieldDef>(field_ground.shape)).value();
  BodyDef mesh_ground = field_ground;
  mesh_ground.shape = mesh_of_height_field(hills);
  std::printf(
      "%d balls (%g m) or capsules (%g m, core %g m) thrown onto the rolling hills, 10 s at 60 Hz, "
      "one thread, %d rounds\n",
      bodies, size, 0.6 * size, 2.4 * size, rounds);
  const char* names[4] = {"balls, heightfield", "capsules, heightfield", "balls, mesh",
                          "capsules, mesh"};
  std::vector<double> ms[4];
  double deepest[4] = {0, 0, 0, 0};
  for (int round = 0; round < rounds; ++round)
    for (int k = 0; k < 4; ++k) {
      const Run r = run(k < 2 ? field_ground : mesh_ground, hills, k % 2 == 1, bodies, size);
      ms[k].push_back(r.ms_per_step);
      deepest[k] = std::max(deepest[k], r.deepest);
    }
  for (int k = 0; k < 4; ++k) {
    std::sort(ms[k].begin(), ms[k].end());
    std::printf("  %-22s median %7.3f ms a step   sank at most %.4f m\n", names[k],
                ms[k][ms[k].size() / 2], deepest[k]);
  }
  return 0;
}
