// Spheres, capsules and the ground half-space against analytic answers.
#include <gtest/gtest.h>

#include <algorithm>
#include <utility>

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

// A box, and the same box as a hull: GJK and EPA where the box takes the closed forms.
std::pair<Shape, Shape> box_and_equal_hull(const Vec3& half) {
  return {make(BoxDef{half}), make(HullDef{testing::box_corners(half)})};
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
  const auto [box, hull] = box_and_equal_hull(half);
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

TEST(RoundShapes, CapsuleCoreInsideBoxLeavesThroughTheTopFace) {
  const Shape capsule = make(CapsuleDef{0.1, 0.5});
  const Shape box = make(BoxDef{Vec3(1, 1, 1)});
  // Standing upright, its lower core end 0.3 m inside the top face.
  ContactManifold m;
  collide(capsule, at(Vec3(0.2, 0.2, 1 + 0.5 - 0.3)), box, at(Vec3::Zero()), {}, &m);
  ASSERT_GE(m.count, 1);
  EXPECT_NEAR(m.depth, 0.3 + 0.1, 1e-12);
  EXPECT_TRUE(m.normal.isApprox(-Vec3::UnitZ(), 1e-12));
}

// A capsule whose core has entered a box leaves it the shortest way: as deep as EPA finds it on the
// same box as a hull, and moved back by that depth along the normal it just touches. More than
// half of these leave across an edge of the box (a normal off its axes), the rest through a face.
TEST(RoundShapes, CapsuleCoreInsideBoxLeavesTheShortestWay) {
  const Vec3 half(0.6, 0.3, 0.2);
  const auto [box, hull] = box_and_equal_hull(half);
  const Shape capsule = make(CapsuleDef{0.05, 0.3});
  CollisionSettings settings;
  settings.margin = 0.01;
  testing::Random rng(11);
  int across_edges = 0, inside = 0;
  for (int i = 0; i < 4000; ++i) {
    const Pose body = at(rng.vector(-1, 1), i % 2 == 0 ? Quat::Identity() : rng.rotation());
    const Vec3 local = rng.vector(-1, 1).cwiseProduct(half);
    const Pose capsule_pose = at(body.position + body.orientation * local, rng.rotation());
    ContactManifold mb, mh;
    collide(capsule, capsule_pose, box, body, settings, &mb);
    collide(capsule, capsule_pose, hull, body, settings, &mh);
    ASSERT_GE(mb.count, 1) << i;
    ASSERT_GE(mh.count, 1) << i;
    // (Cores only: a capsule whose core stays outside is the closest points' case.)
    if (mb.depth <= capsule.radius() + 1e-9) continue;
    ++inside;
    ASSERT_NEAR(mb.depth, mh.depth, 1e-9) << i;
    const Pose moved = at(capsule_pose.position - mb.depth * mb.normal, capsule_pose.orientation);
    ContactManifold after;
    collide(capsule, moved, box, body, settings, &after);
    ASSERT_GE(after.count, 1) << i;
    // (A core lying along a face within 1e-3 takes the face's normal, a turn of at most 1.4 mrad
    // from the shortest way, and two points: moved along it, it is left that much inside.)
    ASSERT_NEAR(after.depth, 0, 1e-9 + (mb.count == 2 ? 1e-6 * mb.depth : 0.0)) << i;
    // The point on the box is on its surface (and on the capsule's, a radius from its core).
    for (int k = 0; k < mb.count; ++k) {
      const Vec3 on_box = body.orientation.conjugate() * (mb.points[k].point_b - body.position);
      ASSERT_NEAR((on_box.cwiseAbs() - half).maxCoeff(), 0, 1e-9) << i;
    }
    const Vec3 normal_in_box = body.orientation.conjugate() * mb.normal;
    if (normal_in_box.cwiseAbs().maxCoeff() < 1 - 1e-9) ++across_edges;
  }
  EXPECT_GT(inside, 2000);
  EXPECT_GT(across_edges, inside / 10);
}

// The same at a millimetre, a kilometre, and with a core a thousand times the box's size (a long
// rod through a small block) or a thousandth of it: EPA's depth on the equal hull to 1e-10 of the
// larger of the two.
TEST(RoundShapes, CapsuleCoreInsideBoxLeavesTheShortestWayAtAnyScale) {
  for (const auto& [scale, ratio] : {std::pair{1e-3, 1.0}, {1e3, 1.0}, {1.0, 1e3}, {1.0, 1e-3}}) {
    const Vec3 half = scale * Vec3(0.6, 0.3, 0.2);
    const auto [box, hull] = box_and_equal_hull(half);
    const Shape capsule = make(CapsuleDef{0.05 * scale, 0.3 * scale * ratio});
    CollisionSettings settings;
    settings.margin = 0.01 * scale;
    testing::Random rng(13);
    int inside = 0;
    for (int i = 0; i < 1000; ++i) {
      const Pose body = at(scale * rng.vector(-1, 1), rng.rotation());
      const Vec3 local = rng.vector(-1, 1).cwiseProduct(half);
      const Pose capsule_pose = at(body.position + body.orientation * local, rng.rotation());
      ContactManifold mb, mh;
      collide(capsule, capsule_pose, box, body, settings, &mb);
      collide(capsule, capsule_pose, hull, body, settings, &mh);
      ASSERT_GE(mb.count, 1) << scale << " " << ratio << " " << i;
      ASSERT_GE(mh.count, 1) << scale << " " << ratio << " " << i;
      if (mb.depth <= capsule.radius()) continue;
      ++inside;
      ASSERT_NEAR(mb.depth, mh.depth, 1e-10 * scale * std::max(1.0, ratio))
          << scale << " " << ratio << " " << i;
    }
    EXPECT_GT(inside, 500) << scale << " " << ratio;
  }
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
