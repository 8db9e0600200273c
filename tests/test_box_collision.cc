// Box-box contacts against an exact separating-axis reference, on 100k random pairs drawn from the
// hard cases: generic overlaps, exact face-to-face touching, parallel edges, near-degenerate
// orientations, tiny depths, size ratios up to 1:1000, and positions 1e5 m from the origin; and
// faces of many sides, whose clipped polygon outgrows the clipper's stack buffers.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "box_pairs.h"
#include "physics/collision.h"
#include "test_support.h"

namespace tumble {
namespace {

using testing::BoxPair;
using testing::make_box_pair;
using testing::Random;

struct Tally {
  int checked = 0, overlapping = 0, separated = 0, normal_checked = 0;
};

void check_pairs(NarrowPhaseMethod method, int count, Tally* tally) {
  Random rng(20261122);
  CollisionSettings settings;
  settings.method = method;
  for (int i = 0; i < count; ++i) {
    const BoxPair p = make_box_pair(rng, i);
    const Shape a = Shape::create(BoxDef{p.ha}).value();
    const Shape b = Shape::create(BoxDef{p.hb}).value();
    const testing::ReferenceSat ref = testing::reference_box_sat(p.ha, p.pa, p.hb, p.pb);
    ContactManifold m;
    const std::uint32_t flags = collide(a, p.pa, b, p.pb, settings, &m);
    const double size = std::max(p.ha.maxCoeff(), p.hb.maxCoeff());
    const double tolerance = 1e-9 * size;
    const std::string where = std::string(p.kind) + " pair " + std::to_string(i);
    ASSERT_EQ(flags & (kGjkIterationLimit | kEpaIterationLimit), 0u) << where;
    ++tally->checked;
    if (ref.separation > tolerance) {
      ++tally->separated;
      ASSERT_EQ(m.count, 0) << where << " separated by " << ref.separation;
      continue;
    }
    if (ref.separation > -tolerance) continue;  // touching: either answer is right
    ++tally->overlapping;
    ASSERT_GT(m.count, 0) << where << " overlaps by " << -ref.separation;
    ASSERT_NEAR(m.depth, -ref.separation, tolerance) << where;
    ASSERT_NEAR(m.normal.norm(), 1.0, 1e-12) << where;
    // The normal is unique when no other axis comes within 1e-6 of the best separation.
    if (ref.runner_up < ref.separation - 1e-6 * size) {
      ++tally->normal_checked;
      const double angle = std::acos(std::clamp(m.normal.dot(ref.axis), -1.0, 1.0));
      ASSERT_LT(angle, 1e-6) << where << " normal " << m.normal.transpose() << " expected "
                             << ref.axis.transpose();
    }
    for (int k = 0; k < m.count; ++k) {
      const ContactPoint& c = m.points[k];
      // Points lie on their own surfaces, and their gap is the point's depth along the normal.
      ASSERT_NEAR(testing::box_signed_distance(p.ha, p.pa, c.point_a), 0, 1e-8 * size) << where;
      ASSERT_NEAR(testing::box_signed_distance(p.hb, p.pb, c.point_b), 0, 1e-8 * size) << where;
      ASSERT_LT((c.point_a - c.point_b - c.depth * m.normal).norm(), 1e-8 * size) << where;
      ASSERT_LE(c.depth, -ref.separation + tolerance) << where;
    }
  }
}

TEST(BoxCollision, SatMatchesExactReferenceOn100kPairs) {
  Tally tally;
  check_pairs(NarrowPhaseMethod::kSat, 100000, &tally);
  EXPECT_EQ(tally.checked, 100000);
  // The generator must really produce both outcomes and unique normals, or the test is hollow.
  EXPECT_GT(tally.overlapping, 40000);
  EXPECT_GT(tally.separated, 5000);
  EXPECT_GT(tally.normal_checked, 20000);
}

TEST(BoxCollision, GjkEpaMatchesExactReferenceOn100kPairs) {
  Tally tally;
  check_pairs(NarrowPhaseMethod::kGjkEpa, 100000, &tally);
  EXPECT_GT(tally.overlapping, 40000);
}

TEST(BoxCollision, RestingBoxGivesFourPointsWithStableIds) {
  const Shape a = Shape::create(BoxDef{Vec3(2, 2, 0.5)}).value();
  const Shape b = Shape::create(BoxDef{}).value();
  Pose pa, pb;
  pb.position = Vec3(0.1, -0.2, 0.5 + 0.5 - 0.01);
  ContactManifold first, second;
  collide(a, pa, b, pb, {}, &first);
  ASSERT_EQ(first.count, 4);
  for (int k = 0; k < 4; ++k)
    EXPECT_NEAR(first.points[k].depth, 0.01, 1e-12);
  EXPECT_TRUE(first.normal.isApprox(Vec3::UnitZ(), 1e-12));
  // Slide a little: the same features touch, so the ids must be the same set.
  pb.position += Vec3(0.01, 0.02, 0.001);
  collide(a, pa, b, pb, {}, &second);
  ASSERT_EQ(second.count, 4);
  for (int k = 0; k < 4; ++k) {
    bool found = false;
    for (int j = 0; j < 4; ++j)
      found |= first.points[k].feature_id == second.points[j].feature_id;
    EXPECT_TRUE(found) << "point " << k;
  }
}

// A prism of 40 sides (80 corners), more than the clippers keep on the stack.
Shape many_sided_prism() {
  constexpr int kSides = 40;
  std::vector<Vec3> points;
  for (int k = 0; k < kSides; ++k) {
    const double angle = 2 * M_PI * k / kSides;
    for (double z : {-0.25, 0.25})
      points.push_back(Vec3(std::cos(angle), std::sin(angle), z));
  }
  return Shape::create(HullDef{points}).value();
}

// The widest distance between two of a manifold's points.
double widest_spread(const ContactManifold& m) {
  double widest = 0;
  for (int k = 0; k < m.count; ++k)
    for (int j = 0; j < k; ++j)
      widest = std::max(widest, (m.points[k].point_b - m.points[j].point_b).norm());
  return widest;
}

// Two such prisms face to face, one turned by half a side: their faces' overlap has 80 corners,
// so the clipper's polygon moves to the heap (twice, the second time with the polygon already
// there). The manifold is still the overlap's extent.
TEST(BoxCollision, ManySidedFacesClipToFourSpreadPoints) {
  const Shape prism = many_sided_prism();
  Pose pa, pb;
  pb.orientation = Quat(Eigen::AngleAxisd(M_PI / 40, Vec3::UnitZ()));
  pb.position = Vec3(0, 0, 0.5 - 0.01);
  ContactManifold m;
  collide(prism, pa, prism, pb, {}, &m);
  ASSERT_EQ(m.count, 4);
  EXPECT_TRUE(m.normal.isApprox(Vec3::UnitZ(), 1e-12));
  for (int k = 0; k < 4; ++k) {
    EXPECT_NEAR(m.points[k].depth, 0.01, 1e-12) << k;
    EXPECT_LE(m.points[k].point_b.head<2>().norm(), 1 + 1e-12) << k;
  }
  // The overlap is a disc of radius about 0.997: two of the four points lie across it.
  EXPECT_GT(widest_spread(m), 1.95);
}

// The same prism sunk 1 cm into the ground: 40 corners touch, more candidates than the stack holds.
TEST(BoxCollision, ManyCornersOnTheGroundReduceToFourSpreadPoints) {
  const Shape prism = many_sided_prism();
  const Shape ground = Shape::create(HalfSpaceDef{}).value();
  Pose on_ground;
  on_ground.position = Vec3(0, 0, 0.25 - 0.01);
  ContactManifold m;
  collide(prism, on_ground, ground, Pose{}, {}, &m);
  ASSERT_EQ(m.count, 4);
  EXPECT_TRUE(m.normal.isApprox(-Vec3::UnitZ(), 1e-12));
  EXPECT_NEAR(m.depth, 0.01, 1e-12);
  for (int k = 0; k < 4; ++k)
    EXPECT_NEAR(m.points[k].depth, 0.01, 1e-12) << k;
  EXPECT_GT(widest_spread(m), 1.95);
}

TEST(BoxCollision, CrossedEdgesGiveOnePointBetweenTheEdges) {
  const Shape box = Shape::create(BoxDef{}).value();
  Pose pa, pb;
  // A's top edge along x (rotated 45 deg about x), B's bottom edge along y (45 deg about y).
  pa.orientation = Quat(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitX()));
  pb.orientation = Quat(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitY()));
  const double reach = std::sqrt(0.5);
  pb.position = Vec3(0, 0, 2 * reach - 0.05);
  ContactManifold m;
  collide(box, pa, box, pb, {}, &m);
  ASSERT_EQ(m.count, 1);
  EXPECT_NEAR(m.points[0].depth, 0.05, 1e-12);
  EXPECT_TRUE(m.normal.isApprox(Vec3::UnitZ(), 1e-12));
  EXPECT_NEAR(m.points[0].point_a.z(), reach, 1e-12);
}

TEST(BoxCollision, SpeculativeMarginReportsNegativeDepth) {
  const Shape box = Shape::create(BoxDef{}).value();
  Pose pa, pb;
  pb.position = Vec3(0, 0, 1.03);
  CollisionSettings settings;
  ContactManifold m;
  collide(box, pa, box, pb, settings, &m);
  EXPECT_EQ(m.count, 0);
  settings.margin = 0.05;
  collide(box, pa, box, pb, settings, &m);
  ASSERT_EQ(m.count, 4);
  EXPECT_NEAR(m.points[0].depth, -0.03, 1e-12);
}

}  // namespace
}  // namespace tumble
