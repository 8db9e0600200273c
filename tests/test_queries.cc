// Ray casts (physics/query.h) against closed forms for every shape, against a brute-force pass
// over every body (the query tree must change nothing but the cost), with filters, every hit
// along a ray, any thread count, a world that moved since the last query, and refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "physics/world.h"
#include "test_support.h"

namespace tumble {
namespace {

BodyId add(World* world, ShapeDef shape, const Vec3& position,
           const Quat& orientation = Quat::Identity(), BodyType type = BodyType::kStatic) {
  BodyDef def;
  def.shape = std::move(shape);
  def.position = position;
  def.orientation = orientation;
  def.type = type;
  return world->create_body(def).value();
}

RayCast ray_from(const Vec3& origin, const Vec3& direction, double max_distance = 100) {
  RayCast ray;
  ray.origin = origin;
  ray.direction = direction;
  ray.max_distance = max_distance;
  return ray;
}

TEST(RayCasts, EveryShapeAgainstClosedForms) {
  World world;
  const BodyId sphere = add(&world, SphereDef{1}, Vec3(0, 0, 5));
  // A box turned 45 degrees about z: its corner edge faces -x.
  const Quat turned(Eigen::AngleAxisd(std::numbers::pi / 4, Vec3::UnitZ()));
  const BodyId box = add(&world, BoxDef{Vec3(1, 1, 1)}, Vec3(10, 0, 0), turned);
  // A capsule lying along x (its axis is the body's z).
  const Quat lying(Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitY()));
  const BodyId capsule = add(&world, CapsuleDef{0.5, 2}, Vec3(0, 10, 0), lying);

  RayHit hit = world.cast_ray(ray_from(Vec3(0, 0, 0), Vec3(0, 0, 2))).value();
  ASSERT_TRUE(hit.hit());
  EXPECT_EQ(hit.body, sphere);
  EXPECT_NEAR(hit.distance, 4, 1e-12);
  EXPECT_NEAR(hit.fraction, 0.04, 1e-14);
  EXPECT_TRUE(hit.point.isApprox(Vec3(0, 0, 4), 1e-12));
  EXPECT_TRUE(hit.normal.isApprox(Vec3(0, 0, -1), 1e-12));

  // Along +x at y = 0.5 the turned box's face x - y = -sqrt(2) (+10) is met at x = 10 - sqrt 2 + 0.5.
  hit = world.cast_ray(ray_from(Vec3(0, 0.5, 0), Vec3(1, 0, 0))).value();
  ASSERT_TRUE(hit.hit());
  EXPECT_EQ(hit.body, box);
  EXPECT_NEAR(hit.point.x(), 10 - std::sqrt(2.0) + 0.5, 1e-12);
  EXPECT_TRUE(hit.normal.isApprox(Vec3(-1, 1, 0).normalized(), 1e-12));

  // Down onto the lying capsule's side at x = 1 (within its core), and onto its end cap.
  hit = world.cast_ray(ray_from(Vec3(1, 10, 5), Vec3(0, 0, -1))).value();
  ASSERT_TRUE(hit.hit());
  EXPECT_EQ(hit.body, capsule);
  EXPECT_NEAR(hit.distance, 4.5, 1e-12);
  EXPECT_TRUE(hit.normal.isApprox(Vec3(0, 0, 1), 1e-12));
  hit = world.cast_ray(ray_from(Vec3(-9, 10, 0), Vec3(1, 0, 0))).value();
  ASSERT_TRUE(hit.hit());
  EXPECT_NEAR(hit.point.x(), -2.5, 1e-12);
  EXPECT_TRUE(hit.normal.isApprox(Vec3(-1, 0, 0), 1e-12));

  // Misses: past the sphere's side, short of the box, away from everything.
  EXPECT_FALSE(world.cast_ray(ray_from(Vec3(1.01, 0, 0), Vec3(0, 0, 1))).value().hit());
  EXPECT_FALSE(world.cast_ray(ray_from(Vec3(0, 0.5, 0), Vec3(1, 0, 0), 8)).value().hit());
  EXPECT_FALSE(world.cast_ray(ray_from(Vec3(0, 0, 0), Vec3(0, 0, -1))).value().hit());

  // From inside: distance 0, the normal against the ray.
  hit = world.cast_ray(ray_from(Vec3(0, 0, 5.5), Vec3(1, 0, 0))).value();
  EXPECT_EQ(hit.body, sphere);
  EXPECT_EQ(hit.distance, 0);
  EXPECT_TRUE(hit.normal.isApprox(Vec3(-1, 0, 0), 1e-12));
}

TEST(RayCasts, AHullAndAPlane) {
  World world;
  add(&world, HalfSpaceDef{}, Vec3(0, 0, 0));
  // A tetrahedron with a face on z = 1: (0,0,1), (2,0,1), (0,2,1) and an apex at (0,0,3).
  HullDef tetra{{Vec3(0, 0, 1), Vec3(2, 0, 1), Vec3(0, 2, 1), Vec3(0, 0, 3)}};
  const BodyId hull = add(&world, tetra, Vec3::Zero());
  // Straight up from below its base: the ground first (the ray starts in it, at 0)...
  RayHit hit = world.cast_ray(ray_from(Vec3(0.5, 0.5, -1), Vec3(0, 0, 1))).value();
  EXPECT_EQ(hit.distance, 0);
  // ... and from above the ground, its base at z = 1.
  hit = world.cast_ray(ray_from(Vec3(0.5, 0.5, 0.5), Vec3(0, 0, 1))).value();
  ASSERT_TRUE(hit.hit());
  EXPECT_EQ(hit.body, hull);
  EXPECT_NEAR(hit.distance, 0.5, 1e-12);
  EXPECT_TRUE(hit.normal.isApprox(Vec3(0, 0, -1), 1e-12));
  // Down from above: the slanted face x + y + z = 3 (normal (1,1,1)/sqrt 3) at z = 2.
  hit = world.cast_ray(ray_from(Vec3(0.5, 0.5, 5), Vec3(0, 0, -1))).value();
  EXPECT_EQ(hit.body, hull);
  EXPECT_NEAR(hit.point.z(), 2, 1e-12);
  EXPECT_TRUE(hit.normal.isApprox(Vec3(1, 1, 1).normalized(), 1e-12));
  // Beside it, down to the ground.
  hit = world.cast_ray(ray_from(Vec3(3, 3, 5), Vec3(0, 0, -1))).value();
  EXPECT_NE(hit.body, hull);
  EXPECT_NEAR(hit.distance, 5, 1e-12);
  EXPECT_TRUE(hit.normal.isApprox(Vec3(0, 0, 1), 1e-15));
}

// Random bodies of every kind, and a brute-force pass over all of them with each body's own test.
struct Crowd {
  World world;
  std::vector<BodyId> ids;
};

void make_crowd(Crowd* c, int count, std::uint64_t seed) {
  testing::Random random(seed);
  for (int i = 0; i < count; ++i) {
    const Vec3 position = random.vector(-10, 10);
    const Quat orientation = random.rotation();
    ShapeDef shape;
    switch (i % 4) {
      case 0: shape = SphereDef{0.2 + random.uniform()}; break;
      case 1: shape = BoxDef{Vec3(0.2, 0.2, 0.2) + random.vector(0, 1)}; break;
      case 2: shape = CapsuleDef{0.2 + 0.5 * random.uniform(), 0.2 + random.uniform()}; break;
      default: {
        HullDef hull;
        for (int k = 0; k < 12; ++k)
          hull.points.push_back(random.vector(-1, 1));
        shape = hull;
      }
    }
    c->ids.push_back(add(&c->world, shape, position, orientation, BodyType::kDynamic));
  }
}

std::vector<RayCast> random_rays(int count, std::uint64_t seed) {
  testing::Random random(seed);
  std::vector<RayCast> rays;
  for (int i = 0; i < count; ++i) {
    RayCast ray = ray_from(random.vector(-15, 15), random.vector(-1, 1), 5 + 40 * random.uniform());
    if (i % 7 == 0) ray.direction = Vec3::UnitX();  // rays along an axis: the tree's edge case
    rays.push_back(ray);
  }
  return rays;
}

// Brute force: every body alone, as a one-body ray of every hit (cast_ray_all with no tree
// pruning); each ray's hit must be the nearest of them. Returns the rays that hit something.
int expect_nearest_of_every_hit(const World& world, const std::vector<RayCast>& rays,
                                const std::vector<RayHit>& hits) {
  int found = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    std::vector<RayHit> all;
    EXPECT_TRUE(world.cast_ray_all(rays[i], 1000, &all).ok());
    if (all.empty()) {
      EXPECT_FALSE(hits[i].hit()) << i;
      continue;
    }
    ++found;
    EXPECT_TRUE(hits[i].hit()) << i;
    EXPECT_EQ(hits[i].body, all[0].body) << i;
    EXPECT_EQ(hits[i].distance, all[0].distance) << i;
    EXPECT_EQ(hits[i].point, all[0].point) << i;
    // The point lies where the distance says along the ray.
    EXPECT_NEAR((hits[i].point - rays[i].origin).norm(), hits[i].distance, 1e-9);
  }
  return found;
}

TEST(RayCasts, TheTreeFindsWhatEveryBodyTestedFindsAndOnAnyThreadCount) {
  Crowd crowd;
  make_crowd(&crowd, 400, 7);
  const std::vector<RayCast> rays = random_rays(3000, 11);
  std::vector<RayHit> hits(rays.size());
  ASSERT_TRUE(crowd.world.cast_rays(rays, hits).is_ok());
  const int found = expect_nearest_of_every_hit(crowd.world, rays, hits);
  // The test means something: hundreds of hits and of misses (776 and 2224 with these seeds).
  EXPECT_GT(found, 500);
  EXPECT_GT(static_cast<int>(rays.size()) - found, 500);
  // Two threads: the same bits.
  WorldSettings two = crowd.world.settings();
  two.threads = 2;
  ASSERT_TRUE(crowd.world.set_settings(two).is_ok());
  std::vector<RayHit> again(rays.size());
  ASSERT_TRUE(crowd.world.cast_rays(rays, again).is_ok());
  for (std::size_t i = 0; i < rays.size(); ++i) {
    EXPECT_EQ(again[i].body, hits[i].body);
    EXPECT_EQ(again[i].distance, hits[i].distance);
    EXPECT_EQ(again[i].normal, hits[i].normal);
  }
}

TEST(RayCasts, BodiesAsLargeAsTheCrowdFindWhatEveryBodyTestedFinds) {
  // A slab under the crowd and a wall through it, each as wide as the crowd, and a box half as
  // wide: the tree gives bodies of a quarter of everything's extent a child of its root, apart
  // from the small ones (query_index.h). Their hits and the crowd's are still the nearest.
  Crowd crowd;
  make_crowd(&crowd, 200, 13);
  crowd.ids.push_back(add(&crowd.world, BoxDef{Vec3(12, 12, 0.5)}, Vec3(0, 0, -11)));
  crowd.ids.push_back(add(&crowd.world, BoxDef{Vec3(0.2, 12, 6)}, Vec3(3, 0, 0),
                          Quat(Eigen::AngleAxisd(0.3, Vec3::UnitZ()))));
  crowd.ids.push_back(add(&crowd.world, BoxDef{Vec3(6, 2, 2)}, Vec3(-4, 5, 4)));
  const std::vector<RayCast> rays = random_rays(2000, 17);
  std::vector<RayHit> hits(rays.size());
  ASSERT_TRUE(crowd.world.cast_rays(rays, hits).is_ok());
  const int found = expect_nearest_of_every_hit(crowd.world, rays, hits);
  int on_large = 0;
  for (const RayHit& hit : hits)
    for (std::size_t large = crowd.ids.size() - 3; large < crowd.ids.size(); ++large)
      on_large += hit.hit() && hit.body == crowd.ids[large];
  // Hits on the large bodies and on the small ones both.
  EXPECT_GT(on_large, 100);
  EXPECT_GT(found - on_large, 100);
}

TEST(RayCasts, BruteForceOverEveryBodyAgrees) {
  // The brute force above shares the tree's walk; this one does not: every body is removed but
  // one, in turn, and the ray cast against that one alone.
  Crowd crowd;
  make_crowd(&crowd, 24, 3);
  const std::vector<RayCast> rays = random_rays(400, 5);
  std::vector<RayHit> hits(rays.size());
  ASSERT_TRUE(crowd.world.cast_rays(rays, hits).is_ok());
  std::vector<RayHit> nearest(rays.size());
  const std::string state = crowd.world.save_state();
  for (std::size_t b = 0; b < crowd.ids.size(); ++b) {
    World alone = World::from_state(crowd.world.settings(), state).value();
    for (std::size_t other = 0; other < crowd.ids.size(); ++other)
      if (other != b) ASSERT_TRUE(alone.remove_body(crowd.ids[other]).is_ok());
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const RayHit hit = alone.cast_ray(rays[i]).value();
      if (hit.hit() && (!nearest[i].hit() || hit.distance < nearest[i].distance)) nearest[i] = hit;
    }
  }
  for (std::size_t i = 0; i < rays.size(); ++i) {
    ASSERT_EQ(hits[i].hit(), nearest[i].hit()) << i;
    if (!hits[i].hit()) continue;
    EXPECT_EQ(hits[i].body, nearest[i].body) << i;
    EXPECT_NEAR(hits[i].distance, nearest[i].distance, 1e-9) << i;
  }
}

TEST(RayCasts, FiltersEveryHitAndAWorldThatMoved) {
  World world;
  std::vector<BodyId> row;
  for (int k = 0; k < 5; ++k)
    row.push_back(add(&world, BoxDef{Vec3(0.25, 0.25, 0.25)}, Vec3(2.0 * (k + 1), 0, 0)));
  BodyDef ghost_def;
  ghost_def.shape = SphereDef{0.5};
  ghost_def.type = BodyType::kStatic;
  ghost_def.position = Vec3(1, 0, 0);
  ghost_def.filter.layers = 2;
  const BodyId ghost = world.create_body(ghost_def).value();

  RayCast ray = ray_from(Vec3(0, 0, 0), Vec3(1, 0, 0));
  EXPECT_EQ(world.cast_ray(ray).value().body, ghost);
  ray.mask = ~std::uint32_t{2};  // not layer 2: through the ghost to the first box
  EXPECT_EQ(world.cast_ray(ray).value().body, row[0]);

  std::vector<RayHit> all;
  Result<bool> more = world.cast_ray_all(ray, 3, &all);
  ASSERT_TRUE(more.ok());
  EXPECT_TRUE(more.value());
  ASSERT_EQ(all.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(all[k].body, row[k]);
    EXPECT_NEAR(all[k].distance, 2.0 * (k + 1) - 0.25, 1e-12);
  }
  ASSERT_TRUE(world.cast_ray_all(ray, 10, &all).ok());
  EXPECT_EQ(all.size(), 5u);

  // The first box moved away, the second removed: the next query sees the third.
  BodyMotion away;
  away.position = Vec3(0, 50, 0);
  ASSERT_TRUE(world.set_motion(row[0], away).is_ok());
  ASSERT_TRUE(world.remove_body(row[1]).is_ok());
  EXPECT_EQ(world.cast_ray(ray).value().body, row[2]);
  // A falling sphere is found where the step left it.
  const BodyId ball = add(&world, SphereDef{0.5}, Vec3(20, 0, 10), Quat::Identity(),
                          BodyType::kDynamic);
  const RayCast down = ray_from(Vec3(20, 0, 20), Vec3(0, 0, -1));
  EXPECT_NEAR(world.cast_ray(down).value().distance, 9.5, 1e-12);
  ASSERT_TRUE(world.step(0.5).is_ok());
  const RayHit after = world.cast_ray(down).value();
  EXPECT_EQ(after.body, ball);
  EXPECT_LT(world.body(ball)->position().z(), 9);
  EXPECT_NEAR(after.point.z(), world.body(ball)->position().z() + 0.5, 1e-12);
}

TEST(RayCasts, BadRaysAreRefusedNamingTheField) {
  World world;
  add(&world, SphereDef{1}, Vec3(0, 0, 5));
  auto refused = [&](const RayCast& ray, const std::string& field) {
    Result<RayHit> hit = world.cast_ray(ray);
    ASSERT_FALSE(hit.ok()) << field;
    EXPECT_EQ(hit.error().rfind(field + ":", 0), 0u) << hit.error();
  };
  refused(ray_from(Vec3(0, 0, 0), Vec3::Zero()), "direction");
  refused(ray_from(Vec3(0, 0, 0), Vec3(NAN, 0, 1)), "direction");
  refused(ray_from(Vec3(INFINITY, 0, 0), Vec3(0, 0, 1)), "origin");
  refused(ray_from(Vec3(0, 0, 0), Vec3(0, 0, 1), 0), "max_distance");
  refused(ray_from(Vec3(0, 0, 0), Vec3(0, 0, 1), INFINITY), "max_distance");
  refused(ray_from(Vec3(0, 0, 0), Vec3(0, 0, 1), 2e10), "max_distance");
  std::vector<RayCast> rays(3, ray_from(Vec3(0, 0, 0), Vec3(0, 0, 1)));
  rays[2].direction = Vec3::Zero();
  std::vector<RayHit> hits(3);
  const Status s = world.cast_rays(rays, hits);
  ASSERT_FALSE(s.is_ok());
  EXPECT_EQ(s.message().rfind("rays[2].direction:", 0), 0u) << s.message();
  EXPECT_FALSE(hits[0].hit());  // nothing was cast
}

TEST(Overlaps, TheBodiesAShapeMeetsAndNoOthers) {
  World world;
  const BodyId ground = add(&world, HalfSpaceDef{}, Vec3::Zero());
  std::vector<BodyId> row;
  for (int k = 0; k < 6; ++k)  // 1 m cubes centred at x = 0, 2, ..., 10, resting on the ground
    row.push_back(add(&world, BoxDef{Vec3(0.5, 0.5, 0.5)}, Vec3(2.0 * k, 0, 0.5)));
  const BodyId ball = add(&world, SphereDef{0.5}, Vec3(4, 3, 0.5));

  OverlapQuery query;
  query.shape = SphereDef{1.6};
  query.pose.position = Vec3(3, 0, 2.0);  // reaches the cubes at x = 2 and 4 (corners 1.18 away)
  std::vector<BodyId> found;
  ASSERT_TRUE(world.overlap(query, 100, &found).ok());
  EXPECT_EQ(found, (std::vector<BodyId>{row[1], row[2]}));
  // Lowered, it meets the ground too (slot 0: first).
  query.pose.position.z() = 1.0;
  ASSERT_TRUE(world.overlap(query, 100, &found).ok());
  EXPECT_EQ(found, (std::vector<BodyId>{ground, row[1], row[2]}));
  // Exactly touching counts: a box whose face lies on the ball's (y = 2.5).
  OverlapQuery slab;
  slab.shape = BoxDef{Vec3(0.5, 0.5, 0.25)};
  slab.pose.position = Vec3(4, 2, 0.75);
  ASSERT_TRUE(world.overlap(slab, 100, &found).ok());
  EXPECT_EQ(found, (std::vector<BodyId>{ball}));
  slab.pose.position.y() = 1.99;  // 1 cm short of the ball
  ASSERT_TRUE(world.overlap(slab, 100, &found).ok());
  EXPECT_TRUE(found.empty());
  // A long box over the whole row, turned: every cube; a mask without layer 1 finds nothing; a
  // bound of 3 keeps the first three.
  OverlapQuery bar;
  bar.shape = BoxDef{Vec3(6, 0.2, 0.2)};
  bar.pose = Pose{Vec3(5, 0, 0.5), Quat(Eigen::AngleAxisd(0.05, Vec3::UnitZ()))};
  ASSERT_TRUE(world.overlap(bar, 100, &found).ok());
  EXPECT_EQ(found, row);
  Result<bool> more = world.overlap(bar, 3, &found);
  ASSERT_TRUE(more.ok());
  EXPECT_TRUE(more.value());
  EXPECT_EQ(found, (std::vector<BodyId>{row[0], row[1], row[2]}));
  bar.mask = ~std::uint32_t{1};
  ASSERT_TRUE(world.overlap(bar, 100, &found).ok());
  EXPECT_TRUE(found.empty());
}

TEST(ClosestPoints, OnEveryShapeAgainstClosedForms) {
  World world;
  const BodyId ball = add(&world, SphereDef{1}, Vec3::Zero());
  const BodyId box = add(&world, BoxDef{Vec3(1, 1, 1)}, Vec3(10, 0, 0));
  const BodyId capsule = add(&world, CapsuleDef{0.5, 2}, Vec3(0, 10, 0));  // along z
  const BodyId ground = add(&world, HalfSpaceDef{}, Vec3(0, 0, -5));
  auto near = [&](BodyId body, const Vec3& point, double max_distance = 100) {
    return world.closest_point(body, point, max_distance).value();
  };
  ClosestPoint c = near(ball, Vec3(0, 3, 4));
  ASSERT_TRUE(c.found);
  EXPECT_NEAR(c.distance, 4, 1e-9);
  EXPECT_TRUE(c.point.isApprox(Vec3(0, 0.6, 0.8), 1e-9));
  EXPECT_TRUE(c.normal.isApprox(Vec3(0, 0.6, 0.8), 1e-9));
  // A box: off a face, off an edge, inside near a face.
  c = near(box, Vec3(13, 0.5, 0));
  EXPECT_NEAR(c.distance, 2, 1e-9);
  EXPECT_TRUE(c.point.isApprox(Vec3(11, 0.5, 0), 1e-9));
  EXPECT_TRUE(c.normal.isApprox(Vec3(1, 0, 0), 1e-9));
  c = near(box, Vec3(13, 3, 0));
  EXPECT_NEAR(c.distance, std::sqrt(8.0), 1e-9);
  EXPECT_TRUE(c.point.isApprox(Vec3(11, 1, 0), 1e-9));
  c = near(box, Vec3(10.9, 0, 0.2));
  EXPECT_NEAR(c.distance, -0.1, 1e-9);
  EXPECT_TRUE(c.point.isApprox(Vec3(11, 0, 0.2), 1e-9));
  EXPECT_TRUE(c.normal.isApprox(Vec3(1, 0, 0), 1e-9));
  // A capsule's side and cap; the ground.
  c = near(capsule, Vec3(3, 10, 1));
  EXPECT_NEAR(c.distance, 2.5, 1e-9);
  c = near(capsule, Vec3(0, 10, 5));
  EXPECT_NEAR(c.distance, 2.5, 1e-9);
  EXPECT_TRUE(c.point.isApprox(Vec3(0, 10, 2.5), 1e-9));
  c = near(ground, Vec3(7, 7, 2));
  EXPECT_NEAR(c.distance, 7, 1e-9);
  EXPECT_TRUE(c.normal.isApprox(Vec3(0, 0, 1), 1e-12));
  // Beyond max_distance: not found.
  EXPECT_FALSE(near(ball, Vec3(0, 0, 3), 1.5).found);
  EXPECT_TRUE(near(ball, Vec3(0, 0, 3), 2.5).found);
  // Refusals.
  EXPECT_EQ(world.closest_point(BodyId{99, 0}, Vec3::Zero(), 1).error().rfind("body:", 0), 0u);
  EXPECT_EQ(world.closest_point(ball, Vec3(NAN, 0, 0), 1).error().rfind("point:", 0), 0u);
  EXPECT_EQ(world.closest_point(ball, Vec3::Zero(), 0).error().rfind("max_distance:", 0), 0u);
}

TEST(Overlaps, BadShapesAreRefusedNamingTheField) {
  World world;
  std::vector<BodyId> found;
  OverlapQuery query;
  query.shape = SphereDef{-1};
  Result<bool> refused = world.overlap(query, 10, &found);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().rfind("shape.radius", 0), 0u) << refused.error();
  query.shape = HalfSpaceDef{};
  EXPECT_EQ(world.overlap(query, 10, &found).error().rfind("shape:", 0), 0u);
  query.shape = SphereDef{1};
  query.pose.position = Vec3(NAN, 0, 0);
  EXPECT_EQ(world.overlap(query, 10, &found).error().rfind("position:", 0), 0u);
  query.pose.position = Vec3::Zero();
  query.pose.orientation = Quat(2, 0, 0, 0);
  EXPECT_EQ(world.overlap(query, 10, &found).error().rfind("orientation:", 0), 0u);
}

ShapeCast cast_of(ShapeDef shape, const Vec3& from, const Vec3& translation,
                  const Quat& orientation = Quat::Identity()) {
  ShapeCast cast;
  cast.shape = std::move(shape);
  cast.pose = {from, orientation};
  cast.translation = translation;
  return cast;
}

TEST(ShapeCasts, AgainstClosedForms) {
  World world;
  const BodyId ground = add(&world, HalfSpaceDef{}, Vec3::Zero());
  const BodyId ball = add(&world, SphereDef{1}, Vec3(10, 1.5, 3));
  // A ball of 0.5 swept along x at z = 3, y = 0.3: it first touches the ball of 1 (centre 1.2
  // off its line) where the centres are 1.5 apart, x = 10 - sqrt(1.5^2 - 1.2^2) = 9.1. The answer
  // is where the gap first falls below the tolerance: along the path, within the tolerance over
  // the cosine of the approach (0.9 / 1.5).
  const double length = 20;
  Result<ShapeHit> hit =
      world.cast_shape(cast_of(SphereDef{0.5}, Vec3(0, 0.3, 3), Vec3(length, 0, 0)));
  ASSERT_TRUE(hit) << hit.status().message();
  ASSERT_TRUE(hit.value().hit());
  EXPECT_EQ(hit.value().body, ball);
  EXPECT_TRUE(hit.value().converged);
  EXPECT_LE(hit.value().fraction * length, 9.1 + 1e-12);
  EXPECT_GE(hit.value().fraction * length, 9.1 - kShapeCastTolerance * 1.5 / 0.9);
  const Vec3 at(hit.value().fraction * length, 0.3, 3);
  EXPECT_LT((hit.value().normal - (at - Vec3(10, 1.5, 3)).normalized()).norm(), 1e-5);
  EXPECT_LT((hit.value().point - (Vec3(10, 1.5, 3) + hit.value().normal)).norm(), 1e-5);
  // A head-on approach: the ball of 0.5 centred on the other's line meets it at x = 8.5.
  hit = world.cast_shape(cast_of(SphereDef{0.5}, Vec3(0, 1.5, 3), Vec3(length, 0, 0)));
  ASSERT_TRUE(hit.value().hit());
  EXPECT_NEAR(hit.value().fraction * length, 8.5, kShapeCastTolerance);
  EXPECT_LT((hit.value().point - Vec3(9, 1.5, 3)).norm(), 1e-5);
  EXPECT_LT((hit.value().normal - Vec3(-1, 0, 0)).norm(), 1e-9);
  // A box turned 45 degrees about z dropped on the ground from 5 m: its bottom face lands when
  // its centre is at 0.5, 4.5 m down 10.
  const Quat turned(Eigen::AngleAxisd(std::numbers::pi / 4, Vec3::UnitZ()));
  hit = world.cast_shape(cast_of(BoxDef{Vec3(0.5, 0.5, 0.5)}, Vec3(-5, 0, 5), Vec3(0, 0, -10),
                                 turned));
  ASSERT_TRUE(hit.value().hit());
  EXPECT_EQ(hit.value().body, ground);
  EXPECT_NEAR(hit.value().fraction, 0.45, 1e-12);
  EXPECT_NEAR(hit.value().point.z(), 0, 1e-9);
  EXPECT_LT((hit.value().normal - Vec3::UnitZ()).norm(), 1e-12);
  // A capsule lying along x swept sideways into the box-shaped body's face.
  const BodyId wall = add(&world, BoxDef{Vec3(0.1, 2, 2)}, Vec3(-10, 0, 5));
  CapsuleDef lying{0.25, 1};
  const Quat along_x(Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitY()));
  hit = world.cast_shape(cast_of(lying, Vec3(-20, 0, 5), Vec3(10, 0, 0), along_x));
  ASSERT_TRUE(hit.value().hit());
  EXPECT_EQ(hit.value().body, wall);
  // The capsule's end (centre - 1.25) meets the wall's face at -10.1: centre at -11.35.
  EXPECT_NEAR(hit.value().fraction * 10, -11.35 + 20, 1e-6);
  // Already overlapping: fraction 0. Nothing in the way: no hit.
  hit = world.cast_shape(cast_of(SphereDef{0.5}, Vec3(10, 1.5, 3.2), Vec3(1, 0, 0)));
  ASSERT_TRUE(hit.value().hit());
  EXPECT_EQ(hit.value().fraction, 0);
  hit = world.cast_shape(cast_of(SphereDef{0.5}, Vec3(0, 50, 3), Vec3(10, 0, 0)));
  EXPECT_FALSE(hit.value().hit());
}

// Each body in a layer of its own: the nearest hit over all of them must be the earliest of the
// casts against each body alone, to the bit, with any thread count.
TEST(ShapeCasts, TheNearestOfEveryBodyCastAloneOnAnyThreadCount) {
  Crowd crowd;
  make_crowd(&crowd, 32, 11);
  for (int k = 0; k < 32; ++k) {
    BodyMotion motion;
    motion.filter = CollisionFilter{1u << k, 0xFFFFFFFF};
    ASSERT_TRUE(crowd.world.set_motion(crowd.ids[k], motion).is_ok());
  }
  testing::Random random(5);
  std::vector<ShapeCast> casts;
  const ShapeDef shapes[3] = {SphereDef{0.3}, BoxDef{Vec3(0.3, 0.2, 0.4)}, CapsuleDef{0.2, 0.3}};
  for (int i = 0; i < 120; ++i) {
    // Aimed near a body, 1.5 times as far as it: many hit, some miss.
    const Vec3 from = random.vector(-15, 15);
    const Vec3 aim = crowd.world.body(crowd.ids[i % 32])->position() + random.vector(-1.5, 1.5);
    casts.push_back(cast_of(shapes[i % 3], from, 1.5 * (aim - from), random.rotation()));
  }
  std::vector<ShapeHit> hits(casts.size());
  ASSERT_TRUE(crowd.world.cast_shapes(casts, hits).is_ok());
  int hit_count = 0;
  for (std::size_t i = 0; i < casts.size(); ++i) {
    ShapeHit earliest;
    for (int k = 0; k < 32; ++k) {
      ShapeCast alone = casts[i];
      alone.mask = 1u << k;
      const ShapeHit h = crowd.world.cast_shape(alone).value();
      if (h.hit() && (!earliest.hit() || h.fraction < earliest.fraction)) earliest = h;
    }
    ASSERT_EQ(hits[i].hit(), earliest.hit()) << i;
    if (!earliest.hit()) continue;
    ++hit_count;
    EXPECT_EQ(hits[i].body, earliest.body) << i;
    EXPECT_EQ(hits[i].fraction, earliest.fraction) << i;
    EXPECT_EQ(hits[i].point, earliest.point) << i;
    EXPECT_TRUE(hits[i].converged) << i;
  }
  EXPECT_GT(hit_count, 60);
  EXPECT_LT(hit_count, 120);
  WorldSettings one_thread = crowd.world.settings();
  one_thread.threads = 1;
  ASSERT_TRUE(crowd.world.set_settings(one_thread).is_ok());
  std::vector<ShapeHit> again(casts.size());
  ASSERT_TRUE(crowd.world.cast_shapes(casts, again).is_ok());
  for (std::size_t i = 0; i < casts.size(); ++i) {
    EXPECT_EQ(again[i].body, hits[i].body);
    EXPECT_EQ(again[i].fraction, hits[i].fraction);
  }
}

TEST(ShapeCasts, BadCastsAreRefusedNamingTheField) {
  World world;
  add(&world, SphereDef{1}, Vec3::Zero());
  EXPECT_EQ(world.cast_shape(cast_of(HalfSpaceDef{}, Vec3::Zero(), Vec3::UnitX()))
                .status()
                .message(),
            "shape: a half-space holds half the world and cannot be swept");
  EXPECT_EQ(world.cast_shape(cast_of(SphereDef{1}, Vec3::Zero(), Vec3(NAN, 0, 0)))
                .status()
                .message(),
            "translation: must be finite");
  EXPECT_EQ(world.cast_shape(cast_of(SphereDef{1}, Vec3::Zero(), Vec3(2e10, 0, 0)))
                .status()
                .message(),
            "translation: longer than 1e10 m");
  std::vector<ShapeCast> casts = {cast_of(SphereDef{1}, Vec3(5, 0, 0), Vec3(-10, 0, 0)),
                                  cast_of(SphereDef{-1}, Vec3(5, 0, 0), Vec3(-10, 0, 0))};
  std::vector<ShapeHit> hits(2);
  hits[0].fraction = 0.25;
  const Status refused = world.cast_shapes(casts, hits);
  EXPECT_NE(refused.message().find("casts[1].shape.radius"), std::string::npos)
      << refused.message();
  EXPECT_EQ(hits[0].fraction, 0.25);  // nothing was cast
  // A batch whose sweeps reach more bodies than it may test is refused before any is tested.
  for (int i = 0; i < 5; ++i)
    add(&world, SphereDef{0.5}, Vec3(3.0 * i + 3, 0, 0));
  casts = {cast_of(SphereDef{0.1}, Vec3(-2, 0, 0), Vec3(20, 0, 0))};
  hits.assign(1, ShapeHit{});
  hits[0].fraction = 0.25;
  const Status too_many = world.cast_shapes(casts, hits, 4);
  EXPECT_EQ(too_many.code(), StatusCode::kResourceExhausted);
  EXPECT_NE(too_many.message().find("more than the 4 bodies"), std::string::npos)
      << too_many.message();
  EXPECT_EQ(hits[0].fraction, 0.25);
  ASSERT_TRUE(world.cast_shapes(casts, hits, 6).is_ok());
  // Head-on into the ball of 1 at the origin: the cast's centre stops at x = -1.1.
  EXPECT_NEAR(hits[0].fraction * 20, 0.9, kShapeCastTolerance);
}

}  // namespace
}  // namespace tumble
