// What the heightfield and mesh tests share: a grid of heights from a function, bodies added in
// one line, stepping, the height a body comes to rest at, where a sliding box stops, and the
// nearest front a ray meets by brute force over every triangle.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <functional>

#include "physics/world.h"

namespace tumble::terrain_testing {

inline constexpr double kDt = 1.0 / 60;

inline HeightFieldDef field_of(std::uint32_t nx, std::uint32_t ny, double spacing,
                               const std::function<double(double, double)>& height) {
  HeightFieldDef def;
  def.samples_x = nx;
  def.samples_y = ny;
  def.spacing_x = def.spacing_y = spacing;
  for (std::uint32_t j = 0; j < ny; ++j)
    for (std::uint32_t i = 0; i < nx; ++i)
      def.heights.push_back(height((i - 0.5 * (nx - 1)) * spacing, (j - 0.5 * (ny - 1)) * spacing));
  return def;
}

inline BodyId add_static(World* world, const ShapeDef& shape,
                         const Vec3& position = Vec3::Zero()) {
  BodyDef def;
  def.shape = shape;
  def.type = BodyType::kStatic;
  def.position = position;
  return world->create_body(def).value();
}

inline BodyId add_dynamic(World* world, const ShapeDef& shape, const Vec3& position,
                          const Vec3& velocity = Vec3::Zero()) {
  BodyDef def;
  def.shape = shape;
  def.mass = 1;
  def.position = position;
  def.linear_velocity = velocity;
  return world->create_body(def).value();
}

inline void run(World* world, int steps) {
  for (int i = 0; i < steps; ++i)
    ASSERT_TRUE(world->step(kDt).is_ok());
}

// The height `body` dropped at `at` on `ground` comes to rest at after 2 s.
inline double rest_height(const ShapeDef& ground, const ShapeDef& body, const Vec3& at) {
  World world;
  add_static(&world, ground);
  const BodyId id = add_dynamic(&world, body, at);
  run(&world, 120);
  return world.body(id)->position().z();
}

// Where a box sliding across `ground` stops: 0.5 m, friction 0.5, sent at 5 m/s from (-12, -3.1)
// at an angle to the grid (over many inner edges and both diagonals' directions), after 3 s.
inline constexpr double kSlideStartX = -12, kSlideStartY = -3.1;
inline Vec3 slide_stop(const ShapeDef& ground) {
  World world;
  add_static(&world, ground);
  BodyDef box;
  box.shape = BoxDef{Vec3(0.25, 0.25, 0.25)};
  box.mass = 1;
  box.friction = 0.5;
  box.position = Vec3(kSlideStartX, kSlideStartY, 0.25);
  box.linear_velocity = Vec3(4.5, 2.18, 0);  // 5 m/s
  const BodyId id = world.create_body(box).value();
  run(&world, 180);
  return world.body(id)->position();
}

// Every one of `count` triangles (`triangle(t)`), the nearest front within max_t; past max_t if
// none.
template <class Triangle>
double brute_force_ray(std::size_t count, const Triangle& triangle, const Vec3& o, const Vec3& d,
                       double max_t) {
  double best = max_t + 1;
  for (std::size_t t = 0; t < count; ++t) {
    const std::array<Vec3, 3> v = triangle(t);
    const Vec3 n = (v[1] - v[0]).cross(v[2] - v[0]);
    const double along = n.dot(d);
    if (along >= 0) continue;
    const double s = n.dot(v[0] - o) / along;
    if (s < 0 || s > max_t) continue;
    const Vec3 p = o + s * d;
    bool inside = true;
    for (int e = 0; e < 3; ++e)
      inside = inside && (v[(e + 1) % 3] - v[e]).cross(p - v[e]).dot(n) >= -1e-12 * n.squaredNorm();
    if (inside) best = std::min(best, s);
  }
  return best;
}

}  // namespace tumble::terrain_testing
