// Heightfields: refusals that name the field; which edges may push (convex and boundary ones);
// bodies at rest on slopes, valleys and ridges at their analytic heights; a box sliding across a
// triangulated floor stops where it stops on the plane; rays against brute force; snapshots bit
// for bit; a pile dropped on bumpy terrain stays above it.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "physics/world.h"
#include "terrain_support.h"

namespace tumble {
namespace {

using namespace terrain_testing;

std::string refusal(const HeightFieldDef& def) {
  const Result<Shape> shape = Shape::create(def);
  return shape ? "" : shape.status().message();
}

TEST(HeightField, RefusesBadDefinitionsNamingTheField) {
  HeightFieldDef def = field_of(3, 3, 1.0, [](double, double) { return 0.0; });
  EXPECT_EQ(refusal(def), "");
  HeightFieldDef narrow = def;
  narrow.samples_x = 1;
  EXPECT_NE(refusal(narrow).find("samples_x"), std::string::npos);
  HeightFieldDef short_heights = def;
  short_heights.heights.pop_back();
  EXPECT_NE(refusal(short_heights).find("heights: 8 values"), std::string::npos);
  HeightFieldDef nan = def;
  nan.heights[5] = std::nan("");
  EXPECT_NE(refusal(nan).find("heights[5]"), std::string::npos);
  HeightFieldDef flat_spacing = def;
  flat_spacing.spacing_y = 0;
  EXPECT_NE(refusal(flat_spacing).find("spacing_y"), std::string::npos);
  HeightFieldDef huge;
  huge.samples_x = huge.samples_y = 4096;  // 16.7 M samples: over the bound, refused unread
  EXPECT_NE(refusal(huge).find("more than the 4194304"), std::string::npos);

  World world;
  BodyDef moving;
  moving.shape = def;
  moving.mass = 1;
  const Result<BodyId> made = world.create_body(moving);
  ASSERT_FALSE(made);
  EXPECT_NE(made.status().message().find("heightfield must be static"), std::string::npos);
  EXPECT_EQ(world.body_count(), 0u);
}

TEST(HeightField, OnlyConvexAndBoundaryEdgesAreActive) {
  // Flat: only the boundary pushes sideways.
  const HeightField flat =
      HeightField::create(field_of(5, 5, 1.0, [](double, double) { return 0.0; })).value();
  for (std::size_t t = 0; t < flat.triangle_count(); ++t)
    for (int e = 0; e < 3; ++e)
      EXPECT_EQ((flat.active_edges(t) >> e) & 1, flat.neighbour(t, e) < 0 ? 1 : 0);
  // A ridge along y = 0 (the grid's middle row): the edges on it are convex; a valley's are not.
  for (double sign : {-1.0, 1.0}) {
    const HeightField ridge = HeightField::create(field_of(5, 5, 1.0, [&](double, double y) {
                                return sign * -std::abs(y);
                              })).value();
    int active_inner = 0;
    for (std::size_t t = 0; t < ridge.triangle_count(); ++t)
      for (int e = 0; e < 3; ++e)
        if (ridge.neighbour(t, e) >= 0 && ((ridge.active_edges(t) >> e) & 1)) {
          const std::array<Vec3, 3> v = ridge.triangle(t);
          EXPECT_EQ(v[e].y(), 0.0);
          EXPECT_EQ(v[(e + 1) % 3].y(), 0.0);
          ++active_inner;
        }
    EXPECT_EQ(active_inner, sign > 0 ? 8 : 0);  // four cells a side of the ridge, one edge each
  }
}

// A unit box's lowest height at rest on `ground`, after two seconds.
TEST(HeightField, BodiesRestOnFlatTerrainAsOnThePlane) {
  const HeightFieldDef floor = field_of(21, 21, 0.5, [](double, double) { return 0.0; });
  for (const ShapeDef& body : {ShapeDef{BoxDef{Vec3(0.3, 0.2, 0.1)}}, ShapeDef{SphereDef{0.2}},
                               ShapeDef{CapsuleDef{0.1, 0.3}}}) {
    const Vec3 at(0.13, -0.41, 0.5);
    const double on_plane = rest_height(HalfSpaceDef{}, body, at);
    const double on_field = rest_height(floor, body, at);
    EXPECT_NEAR(on_field, on_plane, 1e-9);
  }
}

TEST(HeightField, SlidingBoxStopsWhereItStopsOnThePlane) {
  // Across a floor of 0.5 m cells (slide_stop).
  const HeightFieldDef floor = field_of(81, 81, 0.5, [](double, double) { return 0.0; });
  const Vec3 on_plane = slide_stop(HalfSpaceDef{});
  const Vec3 on_field = slide_stop(floor);
  EXPECT_GT((on_plane - Vec3(kSlideStartX, kSlideStartY, 0.25)).norm(), 2.0);  // it did slide
  EXPECT_LT((on_field - on_plane).norm(), 1e-6);
}

TEST(HeightField, SphereRestsInAValleyAndOnARidge) {
  // Slopes of 1 in 2 along y: a sphere of radius r in the V touches both slopes, its centre
  // r / cos(a) above the valley line; on the ridge it sits on the ridge line, r above it.
  const double r = 0.3, slope = 0.5;
  const double a = std::atan(slope);
  const HeightFieldDef valley =
      field_of(9, 9, 0.5, [&](double, double y) { return slope * std::abs(y); });
  const HeightFieldDef ridge =
      field_of(9, 9, 0.5, [&](double, double y) { return -slope * std::abs(y); });
  EXPECT_NEAR(rest_height(valley, SphereDef{r}, Vec3(0.1, 0, 1)), r / std::cos(a), 1e-4);
  EXPECT_NEAR(rest_height(ridge, SphereDef{r}, Vec3(0.1, 0, 1)), r, 1e-4);
  // A box across the ridge rests on the ridge line with its face level.
  EXPECT_NEAR(rest_height(ridge, BoxDef{Vec3(0.2, 0.2, 0.1)}, Vec3(0.1, 0, 1)), 0.1, 1e-4);
}

TEST(HeightField, RaysMeetTheNearestTriangleAsBruteForceDoes) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(-1, 1);
  const HeightFieldDef def = field_of(33, 25, 0.37, [&](double x, double y) {
    return 0.4 * std::sin(1.3 * x) * std::cos(0.9 * y) + 0.05 * unit(random);
  });
  World world;
  const Vec3 at(2, -1, 0.5);
  add_static(&world, def, at);
  const HeightField field = HeightField::create(def).value();
  int hits = 0;
  for (int k = 0; k < 2000; ++k) {
    const Vec3 origin(5 * unit(random), 4 * unit(random), 2 + unit(random));
    const Vec3 direction =
        Vec3(unit(random), unit(random), -1 - std::abs(unit(random))).normalized();
    RayCast ray;
    ray.origin = origin + at;
    ray.direction = direction;
    ray.max_distance = 10;
    const RayHit hit = world.cast_ray(ray).value();
    const double expected = brute_force_ray(
        field.triangle_count(), [&](std::size_t t) { return field.triangle(t); }, origin,
        direction, 10);
    if (expected > 10) {
      // Misses the surface: it may still enter the solid through a side wall.
      if (hit.hit()) {
        EXPECT_LT(std::abs((origin + hit.distance * direction).x()), 6.0);
      }
      continue;
    }
    ASSERT_TRUE(hit.hit()) << k;
    EXPECT_NEAR(hit.distance, expected, 1e-9) << k;
    ++hits;
  }
  EXPECT_GT(hits, 1000);
}

// 64 bodies dropped on bumpy terrain: no centre ever comes nearer the surface under it than a
// body's half thickness allows; boxes alone come to rest (balls and capsules roll on, and knock
// boxes about, in the mixed pile).
void drop_pile(bool boxes_only) {
  const HeightFieldDef def = field_of(41, 41, 0.5, [](double x, double y) {
    return 0.3 * std::sin(0.8 * x) * std::sin(0.7 * y) + 0.1 * std::cos(2.1 * x + 0.3 * y);
  });
  World world;
  add_static(&world, def);
  std::vector<BodyId> bodies;
  for (int k = 0; k < 64; ++k) {
    const Vec3 at(-3.5 + (k % 8), -3.5 + (k / 8) % 8, 1.5 + 0.2 * (k % 3));
    const int kind = boxes_only ? 2 : k % 3;
    const ShapeDef shape = kind == 0   ? ShapeDef{SphereDef{0.2}}
                           : kind == 1 ? ShapeDef{CapsuleDef{0.12, 0.2}}
                                       : ShapeDef{BoxDef{Vec3(0.2, 0.15, 0.1)}};
    bodies.push_back(add_dynamic(&world, shape, at));
  }
  // The surface under each body, from a world of the terrain alone.
  World terrain;
  add_static(&terrain, def);
  for (int chunk = 0; chunk < 15; ++chunk) {
    run(&world, 20);
    for (std::size_t k = 0; k < bodies.size(); ++k) {
      const BodyView body = world.body(bodies[k]);
      RayCast down;
      down.origin = body.position() + Vec3(0, 0, 5);
      down.direction = -Vec3::UnitZ();
      down.max_distance = 20;
      const RayHit surface = terrain.cast_ray(down).value();
      ASSERT_TRUE(surface.hit());
      // Every body is at least 0.2 m thick about its centre: a centre nearer the surface than
      // 0.05 m has gone into it.
      EXPECT_GT(body.position().z() - surface.point.z(), 0.05) << k << " at " << chunk;
      if (boxes_only && chunk == 14) {
        EXPECT_LT(body.linear_velocity().norm(), 1e-3) << k;
      }
    }
  }
}

TEST(HeightField, PileOfMixedShapesStaysAboveIt) {
  drop_pile(false);
}
TEST(HeightField, PileOfBoxesComesToRestOnIt) {
  drop_pile(true);
}

// A body over more cells than a pair may visit is met on the first kMaxTerrainCells of them, and
// the narrow phase says so; a body over fewer is met whole and raises nothing.
TEST(HeightField, AHugeBodyVisitsABoundedNumberOfCellsAndSaysSo) {
  const Shape field =
      Shape::create(field_of(401, 401, 0.5, [](double, double) { return 0.0; })).value();
  const Shape huge = Shape::create(BoxDef{Vec3(90, 90, 1)}).value();
  const Shape small = Shape::create(BoxDef{Vec3(1, 1, 1)}).value();
  ContactManifold manifold;
  const Pose ground;
  const Pose resting{Vec3(0, 0, 0.999), Quat::Identity()};
  EXPECT_NE(collide(huge, resting, field, ground, CollisionSettings{}, &manifold) &
                kTerrainCellLimit,
            0u);
  EXPECT_GT(manifold.count, 0);  // the cells it did visit still hold it
  EXPECT_EQ(collide(small, resting, field, ground, CollisionSettings{}, &manifold), 0u);
  EXPECT_EQ(manifold.count, 4);
  EXPECT_NEAR(manifold.depth, 0.001, 1e-12);
}

TEST(HeightField, SnapshotsStepBitForBit) {
  const HeightFieldDef def =
      field_of(17, 13, 0.6, [](double x, double y) { return 0.2 * std::sin(x) * std::cos(y); });
  World world;
  add_static(&world, def, Vec3(0.5, 0, -0.2));
  for (int k = 0; k < 12; ++k)
    add_dynamic(&world, BoxDef{Vec3(0.2, 0.2, 0.2)}, Vec3(-2 + 0.8 * (k % 6), (k / 6) - 0.5, 1));
  run(&world, 40);
  const std::string saved = world.save_state();
  World copy;
  ASSERT_TRUE(copy.restore_state(saved).is_ok());
  EXPECT_EQ(copy.save_state(), saved);
  run(&world, 30);
  run(&copy, 30);
  EXPECT_EQ(copy.save_state(), world.save_state());
}

}  // namespace
}  // namespace tumble
