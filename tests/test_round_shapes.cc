// Spheres, capsules and the ground half-space against analytic answers.
#include <gtest/gtest.h>

#include "physics/collision.h"
#include "test_support.h"

namespace tumble {
namespace {

Shape make(const ShapeDef& def) {
  return Shape::create(def).value();
}

Pose at(const Vec3& p, const Quat& q = Quat::Identity()) {
  return {p, q};
}

TEST(RoundShapes, SphereSphere) {
  ContactManifold m;
  collide(make(SphereDef{1}), at(Vec3(0, 0, 0)), make(SphereDef{0.5}), at(Vec3(1.2, 0, 0)), {}, &m);
  ASSERT_EQ(m.count, 1);
  EXPECT_NEAR(m.depth, 0.3, 1e-15);
  EXPECT_TRUE(m.normal.isApprox(Vec3::UnitX()));
  EXPECT_TRUE(m.points[0].point_a.isApprox(Vec3(1, 0, 0)));
  EXPECT_TRUE(m.points[0].point_b.isApprox(Vec3(0.7, 0, 0)));
}

TEST(RoundShapes, SphereOnBoxFaceEdgeAndInside) {
  const Shape box = make(BoxDef{Vec3(1, 1, 1)});
  const Shape ball = make(SphereDef{0.5});
  ContactManifold m;
  collide(ball, at(Vec3(0.2, 0.1, 1.4)), box, at(Vec3::Zero()), {}, &m);
  ASSERT_EQ(m.count, 1);
  EXPECT_NEAR(m.depth, 0.1, 1e-15);
  EXPECT_TRUE(m.normal.isApprox(-Vec3::UnitZ()));
  // Beyond an edge: the normal points from the sphere centre to the edge.
  collide(ball, at(Vec3(1.3, 0, 1.3)), box, at(Vec3::Zero()), {}, &m);
  ASSERT_EQ(m.count, 1);
  EXPECT_NEAR(m.depth, 0.5 - 0.3 * std::sqrt(2.0), 1e-15);
  EXPECT_TRUE(m.normal.isApprox(Vec3(-1, 0, -1).normalized()));
  // Centre inside the box: out through the nearest face.
  collide(ball, at(Vec3(0.1, 0.8, 0)), box, at(Vec3::Zero()), {}, &m);
  ASSERT_EQ(m.count, 1);
  EXPECT_NEAR(m.depth, 0.7, 1e-15);
  EXPECT_TRUE(m.normal.isApprox(-Vec3::UnitY()));
  // Swapped order mirrors the answer.
  ContactManifold swapped;
  collide(box, at(Vec3::Zero()), ball, at(Vec3(0.1, 0.8, 0)), {}, &swapped);
  EXPECT_TRUE(swapped.normal.isApprox(Vec3::UnitY()));
  EXPECT_NEAR(swapped.depth, 0.7, 1e-15);
}

TEST(RoundShapes, SphereAgainstHullMatchesSphereAgainstEqualBox) {
  std::vector<Vec3> corners;
  for (int i = 0; i < 8; ++i)
    corners.emplace_back((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1);
  const Shape hull = make(HullDef{corners});
  const Shape box = make(BoxDef{Vec3(1, 1, 1)});
  const Shape ball = make(SphereDef{0.4});
  testing::Random rng(3);
  for (int i = 0; i < 2000; ++i) {
    const Pose ball_pose = at(rng.vector(-1.5, 1.5));
    const Pose body = at(Vec3::Zero(), rng.rotation());
    ContactManifold mh, mb;
    collide(ball, ball_pose, hull, body, {}, &mh);
    collide(ball, ball_pose, box, body, {}, &mb);
    ASSERT_EQ(mh.count, mb.count) << i;
    if (mb.count == 0) continue;
    ASSERT_NEAR(mh.depth, mb.depth, 1e-9) << i;
  }
}

TEST(RoundShapes, CapsuleLyingOnBoxGivesTwoPoints) {
  const Shape capsule = make(CapsuleDef{0.25, 1.0});
  const Shape box = make(BoxDef{Vec3(2, 2, 0.5)});
  // Capsule axis along x, resting 1 cm deep on the top face.
  const Pose pose =
      at(Vec3(0.3, 0, 0.5 + 0.25 - 0.01), Quat(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitY())));
  ContactManifold m;
  collide(capsule, pose, box, at(Vec3::Zero()), {}, &m);
  ASSERT_EQ(m.count, 2);
  EXPECT_TRUE(m.normal.isApprox(-Vec3::UnitZ(), 1e-12));
  for (int k = 0; k < 2; ++k) {
    EXPECT_NEAR(m.points[k].depth, 0.01, 1e-12);
    EXPECT_NEAR(m.points[k].point_b.z(), 0.5, 1e-12);
  }
  EXPECT_NEAR(std::abs(m.points[0].point_a.x() - m.points[1].point_a.x()), 2.0, 1e-12);
}

// A capsule against a box (the closed form) and against the same box as a hull (GJK): one answer.
TEST(RoundShapes, CapsuleAgainstHullMatchesCapsuleAgainstEqualBox) {
  const Vec3 half(0.6, 0.3, 0.2);
  const Shape hull = make(HullDef{testing::box_corners(half)});
  const Shape box = make(BoxDef{half});
  const Shape capsule = make(CapsuleDef{0.1, 0.25});
  CollisionSettings settings;
  settings.margin = 0.05;
  testing::Random rng(5);
  int touching = 0;
  for (int i = 0; i < 4000; ++i) {
    const Pose capsule_pose = at(rng.vector(-1.1, 1.1), rng.rotation());
    const Pose body = at(Vec3::Zero(), i % 2 == 0 ? Quat::Identity() : rng.rotation());
    ContactManifold mh, mb;
    collide(capsule, capsule_pose, hull, body, settings, &mh);
    collide(capsule, capsule_pose, box, body, settings, &mb);
    ASSERT_EQ(mh.count, mb.count) << i;
    if (mb.count == 0) continue;
    ++touching;
    ASSERT_NEAR(mh.depth, mb.depth, 1e-9) << i;
    ASSERT_TRUE(mh.normal.isApprox(mb.normal, 1e-6)) << i;
    for (int k = 0; k < mb.count; ++k)
      ASSERT_TRUE(mh.points[k].point_a.isApprox(mb.points[k].point_a, 1e-6)) << i;
  }
  EXPECT_GT(touching, 400);
}

TEST(RoundShapes, CapsuleCoreInsideBoxUsesEpa) {
  const Shape capsule = make(CapsuleDef{0.1, 0.5});
  const Shape box = make(BoxDef{Vec3(1, 1, 1)});
  // Standing upright, its lower core end 0.3 m inside the top face.
  ContactManifold m;
  collide(capsule, at(Vec3(0.2, 0.2, 1 + 0.5 - 0.3)), box, at(Vec3::Zero()), {}, &m);
  ASSERT_GE(m.count, 1);
  EXPECT_NEAR(m.depth, 0.3 + 0.1, 1e-12);
  EXPECT_TRUE(m.normal.isApprox(-Vec3::UnitZ(), 1e-12));
}

TEST(RoundShapes, ParallelCapsulesTouchAlongTheirOverlap) {
  const Shape capsule = make(CapsuleDef{0.2, 1.0});
  ContactManifold m;
  collide(capsule, at(Vec3::Zero()), capsule, at(Vec3(0.35, 0, 0.5)), {}, &m);
  ASSERT_EQ(m.count, 2);
  EXPECT_NEAR(m.depth, 0.05, 1e-12);
  EXPECT_TRUE(m.normal.isApprox(Vec3::UnitX(), 1e-12));
  // Crossed capsules touch at one point.
  collide(capsule, at(Vec3::Zero()), capsule,
          at(Vec3(0.3, 0, 0), Quat(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX()))), {}, &m);
  ASSERT_EQ(m.count, 1);
  EXPECT_NEAR(m.depth, 0.1, 1e-12);
}

TEST(HalfSpace, BoxHullSphereCapsuleOnTheGround) {
  const Shape ground = make(HalfSpaceDef{});
  ContactManifold m;
  // A tilted box: only the corners below z = 0 count, deepest first.
  const Pose tilted = at(Vec3(5, 5, 0.6), Quat(Eigen::AngleAxisd(0.3, Vec3::UnitX())));
  collide(make(BoxDef{}), tilted, ground, at(Vec3::Zero()), {}, &m);
  ASSERT_EQ(m.count, 2);
  const double lowest = 0.6 - 0.5 * (std::cos(0.3) + std::sin(0.3));
  EXPECT_NEAR(m.depth, -lowest, 1e-12);
  EXPECT_TRUE(m.normal.isApprox(-Vec3::UnitZ()));
  for (int k = 0; k < m.count; ++k)
    EXPECT_NEAR(m.points[k].point_b.z(), 0, 1e-15);
  // A flat box on the ground: four corners.
  collide(make(BoxDef{}), at(Vec3(0, 0, 0.49)), ground, at(Vec3::Zero()), {}, &m);
  EXPECT_EQ(m.count, 4);
  // A hull with many vertices on its bottom face is reduced to four, keeping the deepest.
  std::vector<Vec3> ring;
  for (int i = 0; i < 16; ++i)
    for (double z : {-0.5, 0.5})
      ring.emplace_back(std::cos(i * M_PI / 8), std::sin(i * M_PI / 8), z + (z < 0 ? 1e-3 * i : 0));
  const Shape ringed = make(HullDef{ring});
  ASSERT_EQ(ringed.polyhedron()->vertices.size(), 32u);
  collide(ringed, at(Vec3(0, 0, 0.4)), ground, at(Vec3::Zero()), {}, &m);
  EXPECT_EQ(m.count, 4);
  EXPECT_NEAR(m.depth, 0.1, 1e-12);
  double deepest_point = 0;
  for (int k = 0; k < m.count; ++k)
    deepest_point = std::max(deepest_point, m.points[k].depth);
  EXPECT_NEAR(deepest_point, 0.1, 1e-12);
  // Sphere and capsule; and the ground as body A flips the normal.
  collide(ground, at(Vec3::Zero()), make(SphereDef{0.5}), at(Vec3(0, 0, 0.4)), {}, &m);
  ASSERT_EQ(m.count, 1);
  EXPECT_NEAR(m.depth, 0.1, 1e-15);
  EXPECT_TRUE(m.normal.isApprox(Vec3::UnitZ()));
  collide(make(CapsuleDef{0.2, 1}),
          at(Vec3(0, 0, 0.15), Quat(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitY()))), ground,
          at(Vec3::Zero()), {}, &m);
  EXPECT_EQ(m.count, 2);
  EXPECT_NEAR(m.depth, 0.05, 1e-12);
  // Far from the origin nothing changes.
  collide(make(BoxDef{}), at(Vec3(1e5, -1e5, 0.49)), ground, at(Vec3(1e5, 0, 0)), {}, &m);
  EXPECT_EQ(m.count, 4);
  EXPECT_NEAR(m.depth, 0.01, 1e-10);
}

}  // namespace
}  // namespace tumble
