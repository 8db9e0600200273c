// Triangle meshes of the shapes, in their body frames, with a normal per vertex: boxes and the
// ground are flat-faced (each face its own vertices), spheres and capsules smooth.
#pragma once

#include <cstdint>
#include <vector>

namespace tumble::viewer {

struct Mesh {
  std::vector<float> vertices;         // x y z nx ny nz per vertex
  std::vector<std::uint32_t> indices;  // three per triangle, counter-clockwise seen from outside
};

// The cube [-1, 1]^3: scaled per instance to a box's half extents.
Mesh unit_box();
// The unit sphere, `rings` latitude bands and `segments` longitude ones.
Mesh unit_sphere(int rings = 16, int segments = 24);
// A capsule of `radius` and `half_height` (z axis): its shape differs with the ratio, so one mesh
// per distinct capsule.
Mesh capsule(float radius, float half_height, int rings = 8, int segments = 24);
// The square [-half, half]^2 at z = 0, facing +z: the ground.
Mesh ground_square(float half);

}  // namespace tumble::viewer
