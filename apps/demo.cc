// tumble-demo: the default scene (boxes over a floor) through the collision pipeline, printing what
// collides. Until the solver lands there is no stepping: it shows the broad and narrow phase.
#include <chrono>
#include <cstdio>
#include <vector>

#include "physics/world.h"

using namespace tumble;

namespace {

// The default scene: a ground plane and a 4 x 4 x 3 lattice of unit boxes, the lowest layer
// resting 1 cm deep in the ground and each layer leaning into the one below.
std::vector<BodyDef> default_scene() {
  std::vector<BodyDef> defs;
  BodyDef ground;
  ground.shape = HalfSpaceDef{};
  ground.type = BodyType::kStatic;
  defs.push_back(ground);
  for (int layer = 0; layer < 3; ++layer)
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) {
        BodyDef box;
        box.shape = BoxDef{Vec3::Constant(0.5)};
        box.mass = 1;
        box.position = Vec3(1.1 * i + 0.3 * layer, 1.1 * j, 0.49 + 0.99 * layer);
        box.orientation = Quat(Eigen::AngleAxisd(0.1 * layer, Vec3::UnitZ()));
        defs.push_back(box);
      }
  BodyDef ball;
  ball.shape = SphereDef{0.3};
  ball.position = Vec3(-1.0, 0, 0.25);
  defs.push_back(ball);
  return defs;
}

}  // namespace

int main() {
  World world;
  const auto ids = world.create_bodies(default_scene());
  if (!ids) {
    std::fprintf(stderr, "tumble-demo: %s\n", ids.error().c_str());
    return 1;
  }
  const auto start = std::chrono::steady_clock::now();
  const auto pairs = world.find_pairs();
  const std::size_t pair_count = pairs.size();
  const auto contacts = world.find_contacts();
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();

  std::printf("Tumble demo: default scene, %zu bodies\n", world.body_count());
  std::printf("broad phase: %zu pairs; narrow phase: %zu touching (%.3f ms)\n\n", pair_count,
              contacts.size(), ms);
  std::printf("%5s %5s  %-10s %-10s %6s %10s  %s\n", "a", "b", "shape a", "shape b", "points",
              "depth [m]", "normal");
  for (const Contact& c : contacts) {
    const Body* a = world.body(c.a);
    const Body* b = world.body(c.b);
    const Vec3& n = c.manifold.normal;
    std::printf("%5u %5u  %-10s %-10s %6d %10.5f  (%+.3f, %+.3f, %+.3f)\n", c.a.index, c.b.index,
                shape_type_name(a->shape.type()), shape_type_name(b->shape.type()),
                c.manifold.count, c.manifold.depth, n.x(), n.y(), n.z());
  }
  if (world.collision_flags() != kCollisionOk)
    std::printf("\nwarning: the narrow phase raised flags 0x%x\n", world.collision_flags());
  return 0;
}
