// Continuous collision: time of impact by conservative advancement, and fast bodies in a world
// that stop at thin walls and floors instead of passing them, without ghost contacts with what
// they only pass by.
#include <gtest/gtest.h>

#include "continuous.h"
#include "scene_runner.h"

namespace tumble::testing {
namespace {

Shape make_shape(const ShapeDef& def) {
  return Shape::create(def).value();
}

SweptMotion moving(const Vec3& start, const Vec3& translation) {
  SweptMotion motion;
  motion.start.position = start;
  motion.translation = translation;
  return motion;
}

TEST(TimeOfImpact, SpheresHeadOnMatchTheAnalyticTime) {
  const Shape a = make_shape(SphereDef{0.5}), b = make_shape(SphereDef{0.25});
  // B flies at A: the surfaces meet after 10 - 0.75 = 9.25 m of the 20 m motion.
  const double target = 0.01, tolerance = 0.0025;
  const ImpactResult hit =
      time_of_impact(a, moving(Vec3::Zero(), Vec3::Zero()), b,
                     moving(Vec3(10, 0, 0), Vec3(-20, 0, 0)), target, tolerance, 32);
  ASSERT_EQ(hit.status, ImpactStatus::kHit);
  const double gap = 10 - 20 * hit.t - 0.75;
  EXPECT_GE(gap, target - 1e-9);
  EXPECT_LE(gap, target + tolerance);
  EXPECT_NEAR(hit.normal.x(), 1, 1e-9);
}

TEST(TimeOfImpact, PassingByIsAMiss) {
  const Shape box = make_shape(BoxDef{Vec3::Constant(0.05)});
  // 20 m past a box 0.3 m to the side: closest approach 0.2 m.
  const ImpactResult result =
      time_of_impact(box, moving(Vec3(0, 0.3, 0), Vec3::Zero()), box,
                     moving(Vec3(-10, 0, 0), Vec3(20, 0, 0)), 0.01, 0.0025, 32);
  EXPECT_EQ(result.status, ImpactStatus::kMiss);
}

TEST(TimeOfImpact, TouchingAtTheStartIsLeftToTheSolver) {
  const Shape box = make_shape(BoxDef{Vec3::Constant(0.5)});
  const ImpactResult result =
      time_of_impact(box, moving(Vec3::Zero(), Vec3::Zero()), box,
                     moving(Vec3(1.005, 0, 0), Vec3(-5, 0, 0)), 0.01, 0.0025, 32);
  EXPECT_EQ(result.status, ImpactStatus::kTouchingAtStart);
}

TEST(TimeOfImpact, SpinningPlateStopsBeforeTheFloor) {
  const Shape floor = make_shape(HalfSpaceDef{});
  const Shape plate = make_shape(BoxDef{Vec3(0.5, 0.5, 0.005)});
  // Flat at 0.3 m, turning 1.6 rad about x: its edge would reach 0.2 m below the floor.
  SweptMotion spin = moving(Vec3(0, 0, 0.3), Vec3::Zero());
  spin.rotation = Vec3(1.6, 0, 0);
  spin.outer_radius = plate.outer_radius();
  const double target = 0.01, tolerance = 0.0025;
  const ImpactResult hit = time_of_impact(floor, SweptMotion{}, plate, spin, target, tolerance, 64);
  ASSERT_EQ(hit.status, ImpactStatus::kHit);
  // The plate's lowest corner at the impact is within [target, target + tolerance] of the floor
  // and no earlier pose went lower (the advancement is conservative).
  auto lowest = [&](double t) {
    const Pose pose = pose_at(spin, t);
    double low = 1e9;
    for (int i = 0; i < 8; ++i) {
      const Vec3 c((i & 1) ? 0.5 : -0.5, (i & 2) ? 0.5 : -0.5, (i & 4) ? 0.005 : -0.005);
      low = std::min(low, (pose.orientation * c + pose.position).z());
    }
    return low;
  };
  EXPECT_GE(lowest(hit.t), target - 1e-9);
  EXPECT_LE(lowest(hit.t), target + tolerance);
  for (int i = 0; i < 100; ++i)
    EXPECT_GT(lowest(hit.t * i / 100), target - 1e-9);
  // The exact answer: sin(angle) 0.5 + 0.005 cos(angle) = 0.3 - gap.
  EXPECT_GT(hit.t * 1.6, std::asin((0.3 - target - tolerance - 0.005) / 0.5));
  EXPECT_LT(hit.t * 1.6, std::asin((0.3 - target) / 0.5));
}

SceneDef wall_scene(const Vec3& start, double speed) {
  SceneDef scene;
  scene.name = "bullet-1000";
  scene.world.gravity = Vec3::Zero();
  BodyDef projectile;
  projectile.shape = BoxDef{Vec3::Constant(0.05)};
  projectile.mass = 1;
  projectile.position = start;
  projectile.linear_velocity = Vec3(speed, 0, 0);
  BodyDef wall;  // 1 cm thick
  wall.shape = BoxDef{Vec3(0.005, 5, 5)};
  wall.type = BodyType::kStatic;
  scene.bodies = {projectile, wall};
  return scene;
}

// A 10 cm box at 1000 m/s (16.7 m per step) against a 1 cm wall, with each solver and from
// several starting offsets (so that the wall falls anywhere within a step).
TEST(Continuous, BoxAt1000MetresPerSecondStopsAtA1CentimetreWall) {
  for (SolverKind kind :
       {SolverKind::kAuto, SolverKind::kPgs, SolverKind::kSoft, SolverKind::kExact}) {
    for (double start : {-20.0, -13.3, -7.77, -1.0}) {
      SceneDef scene = wall_scene(Vec3(start, 0, 0), 1000);
      scene.world.solver.kind = kind;
      World world = build(scene);
      std::uint32_t impacts = 0;
      double farthest = -1e9;
      run(world, 1.0 / 60, 30, [&](long) {
        impacts += world.last_step().continuous_impacts;
        farthest = std::max(farthest, dynamic_bodies(world)[0]->position().x());
      });
      SCOPED_TRACE(std::string(solver_name(kind)) + " from x = " + std::to_string(start));
      // Never beyond touching the wall's near face (x = -0.005 - 0.05), and stopped there.
      EXPECT_LT(farthest, -0.055 + 1e-3);
      EXPECT_LE(dynamic_bodies(world)[0]->linear_velocity().x(), 1e-6);
      EXPECT_GE(impacts, 1u);
      EXPECT_EQ(world.last_step().continuous_limit_hits, 0u);
    }
  }
}

// The sweep, unlike a speculative contact as long as the whole motion, has no ghost contacts: a
// box flying past another 0.2 m away keeps its speed and line.
TEST(Continuous, FastBoxPassingBesideAnotherIsNotTouched) {
  SceneDef scene = wall_scene(Vec3(-20, 0, 0), 1000);
  scene.bodies[1].shape = BoxDef{Vec3::Constant(0.05)};
  scene.bodies[1].position = Vec3(0, 0.3, 0);
  World world = build(scene);
  run(world, 1.0 / 60, 3);
  const BodyView box = dynamic_bodies(world)[0];
  EXPECT_EQ(box.linear_velocity(), Vec3(1000, 0, 0));
  EXPECT_EQ(box.angular_velocity(), Vec3::Zero());
  EXPECT_NEAR(box.position().x(), -20 + 3 * 1000.0 / 60, 1e-9);
  EXPECT_EQ(box.position().y(), 0);
  EXPECT_GT(world.last_step().swept_bodies, 0u);

  // Without the sweep, a speculative contact as long as the motion (16.7 m) stands in for it
  // wherever the bounds swept along the path hold the other box. Flying along x, they do not
  // (the bounds grow along the velocity, not on every side), and the box passes untouched.
  scene.world.solver.continuous = false;
  World along_x = build(scene);
  run(along_x, 1.0 / 60, 3);
  EXPECT_EQ(dynamic_bodies(along_x)[0]->linear_velocity(), Vec3(1000, 0, 0));
  EXPECT_EQ(along_x.last_step().pairs, 0u);
  // Flying diagonally past it at the same 0.3 m, the swept bounds (axis-aligned) hold the other
  // box, and the speculative contact's plane, through its nearest face, deflects the box: a ghost
  // contact, which the sweep (first half) never makes.
  const Vec3 diagonal = Vec3(1, 1, 0).normalized();
  scene.bodies[0].position = -20 * diagonal;
  scene.bodies[0].linear_velocity = 1000 * diagonal;
  scene.bodies[1].position = 0.3 * Vec3(-1, 1, 0).normalized();
  World speculative_only = build(scene);
  run(speculative_only, 1.0 / 60, 3);
  EXPECT_GT((dynamic_bodies(speculative_only)[0]->linear_velocity() - 1000 * diagonal).norm(), 0.1);
  scene.world.solver.continuous = true;
  World swept = build(scene);
  run(swept, 1.0 / 60, 3);
  EXPECT_EQ(dynamic_bodies(swept)[0]->linear_velocity(), 1000 * diagonal);
}

// A 1 cm thick plate spinning at 100 rad/s (1.7 rad per step) just above the floor: it never goes
// through, with continuous collision on (by default).
TEST(Continuous, ThinPlateSpinningFastDoesNotPassTheFloor) {
  for (SolverKind kind : {SolverKind::kAuto, SolverKind::kSoft}) {
    SceneDef scene;
    scene.name = "spinning-plate";
    scene.world.solver.kind = kind;
    BodyDef ground;
    ground.shape = HalfSpaceDef{};
    ground.type = BodyType::kStatic;
    BodyDef plate;
    plate.shape = BoxDef{Vec3(0.5, 0.5, 0.005)};
    plate.mass = 1;
    plate.position = Vec3(0, 0, 0.3);
    plate.angular_velocity = Vec3(100, 0, 0);
    scene.bodies = {ground, plate};
    World world = build(scene);
    double deepest = 0, lowest_centre = 1e9;
    run(world, 1.0 / 60, 180, [&](long) {
      const BodyView body = dynamic_bodies(world)[0];
      deepest = std::max(deepest, corner_depth(body));
      lowest_centre = std::min(lowest_centre, body.position().z());
    });
    SCOPED_TRACE(solver_name(kind));
    EXPECT_LT(deepest, 0.01);
    EXPECT_GT(lowest_centre, 0);
    EXPECT_TRUE(all_finite(world));
  }
}

// A fast ball stopped early by the sweep is left in the state it had at the impact, velocity
// included: keeping the end-of-step velocity would give it the whole step's gravity for part of
// the fall. Symplectic Euler loses m g^2 dt^2 / 2 per step in free fall, so the energy must never
// rise from one step to the next, impact included.
TEST(Continuous, StoppingEarlyAddsNoEnergy) {
  SceneDef scene;
  scene.name = "fast-ball";
  BodyDef ground;
  ground.shape = HalfSpaceDef{};
  ground.type = BodyType::kStatic;
  BodyDef ball;
  ball.shape = SphereDef{0.05};
  ball.mass = 1;
  ball.position = Vec3(0, 0, 3);
  ball.linear_velocity = Vec3(0, 0, -30);  // 0.5 m per step, ten times the radius
  scene.bodies = {ground, ball};
  World world = build(scene);
  double previous = total_energy(world);
  std::uint32_t impacts = 0;
  run(world, 1.0 / 60, 60, [&](long) {
    const double energy = total_energy(world);
    EXPECT_LE(energy, previous + 1e-9);
    previous = energy;
    impacts += world.last_step().continuous_impacts;
  });
  EXPECT_GE(impacts, 1u);
  EXPECT_NEAR(dynamic_bodies(world)[0]->position().z(), 0.05, 0.01);
}

// Scenes without fast bodies sweep nothing.
TEST(Continuous, SlowScenesSweepNothing) {
  SceneDef scene = pile_scene(64);
  World world = build(scene);
  std::uint32_t swept = 0;
  run(world, scene.dt, 120, [&](long) { swept += world.last_step().swept_bodies; });
  EXPECT_EQ(swept, 0u);
  EXPECT_EQ(world.last_step().time.continuous, 0.0);
}

}  // namespace
}  // namespace tumble::testing
