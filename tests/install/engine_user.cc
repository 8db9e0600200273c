// A box dropped on the ground, with the engine an installed Tumble provides.
#include <cstdio>

#include "physics/world.h"

int main() {
  tumble::World world;
  world.create_body({.shape = tumble::HalfSpaceDef{}, .type = tumble::BodyType::kStatic});
  const tumble::BodyId box = world.create_body({.position = tumble::Vec3(0, 0, 2)}).value();
  for (int i = 0; i < 120; ++i)
    world.step(1.0 / 60);
  const double z = world.body(box)->position().z();
  std::printf("box at z = %.4f m after %.1f s\n", z, world.time());
  return z > 0.49 && z < 0.51 ? 0 : 1;  // a unit box rests with its centre half a metre up
}
