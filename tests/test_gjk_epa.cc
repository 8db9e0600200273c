// GJK and EPA on bare primitives with analytic answers, on degenerate simplices, and on random
// convex hulls (where the exact SAT is the reference).
#include <gtest/gtest.h>

#include "epa.h"
#include "gjk.h"
#include "physics/collision.h"
#include "segment.h"
#include "test_support.h"

namespace tumble {
namespace {

using testing::Random;

TEST(Gjk, SphereSphereDistanceAndClosestPoints) {
  const SphereSupport a{Vec3(0, 0, 0), 1.0};
  const SphereSupport b{Vec3(3, 4, 0), 2.0};
  GjkSettings settings;
  settings.relative_gap = 1e-12;
  settings.max_iterations = 200;
  const GjkResult r = gjk_distance(a, b, Vec3(1, 0, 0), settings);
  EXPECT_EQ(r.status, GjkStatus::kSeparated);
  // Smooth shapes converge linearly; the gap criterion bounds the error by about 1e-6 here.
  EXPECT_NEAR(r.distance, 2.0, 1e-6);
  EXPECT_TRUE(r.point_a.isApprox(Vec3(0.6, 0.8, 0), 1e-5));
}

TEST(Gjk, PointToBoxRegions) {
  const BoxSupport box{Vec3(1, 2, 3)};
  struct Case {
    Vec3 point;
    double distance;
  };
  // Face, edge and vertex regions, and a point exactly on a face.
  const Case cases[] = {{Vec3(3, 0, 0), 2.0},
                        {Vec3(2, 3, 0), std::sqrt(2.0)},
                        {Vec3(2, 3, 4), std::sqrt(3.0)},
                        {Vec3(1, 0.5, 0.5), 0.0}};
  for (const Case& c : cases) {
    const GjkResult r = gjk_distance(box, PointSupport{c.point}, Vec3(1, 1, 1));
    EXPECT_NEAR(r.distance, c.distance, 1e-12) << c.point.transpose();
    EXPECT_NE(r.status, GjkStatus::kIterationLimit);
  }
}

TEST(Gjk, OriginOnFaceEdgeAndVertexOfTheDifference) {
  // Two unit cubes touching face to face, edge to edge and corner to corner: distance exactly 0.
  const BoxSupport cube{Vec3(0.5, 0.5, 0.5)};
  for (const Vec3& offset : {Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(1, 1, 1)}) {
    const Transformed<BoxSupport> moved{cube, Mat3::Identity(), offset};
    const GjkResult r = gjk_distance(cube, moved, offset);
    EXPECT_NEAR(r.distance, 0.0, 1e-15) << offset.transpose();
    EXPECT_NE(r.status, GjkStatus::kIterationLimit);
  }
}

TEST(Gjk, ThinSimplexStillConverges) {
  // A needle (1e-7 thick) against a large box: the simplex is long and thin.
  const BoxSupport needle{Vec3(10, 1e-7, 1e-7)};
  const BoxSupport block{Vec3(1, 1, 1)};
  const Transformed<BoxSupport> placed{block, Mat3(Eigen::AngleAxisd(0.3, Vec3::UnitZ())),
                                       Vec3(0.5, 0, 1 + 1e-7 + 2e-9)};
  const GjkResult r = gjk_distance(needle, placed, Vec3(0, 0, 1));
  EXPECT_EQ(r.status, GjkStatus::kSeparated);
  EXPECT_NEAR(r.distance, 2e-9, 1e-15);
}

TEST(Epa, BoxDepthsAlongEachAxis) {
  const BoxSupport cube{Vec3(0.5, 0.5, 0.5)};
  for (int axis = 0; axis < 3; ++axis)
    for (double depth : {0.3, 1e-3, 1e-9, 1e-13}) {
      Vec3 offset = Vec3::Zero();
      offset[axis] = 1 - depth;
      const Transformed<BoxSupport> moved{cube, Mat3::Identity(),
                                          offset + Vec3(0.1, 0.1, 0.1) - 0.1 * Vec3::Unit(axis)};
      const GjkResult g = gjk_distance(cube, moved, offset);
      ASSERT_EQ(g.status, GjkStatus::kIntersecting);
      const EpaResult e = epa_penetration(cube, moved, g.simplex);
      EXPECT_NE(e.status, EpaStatus::kIterationLimit);
      EXPECT_NEAR(e.depth, depth, 1e-12) << "axis " << axis << " depth " << depth;
      EXPECT_NEAR(std::abs(e.normal[axis]), 1.0, 1e-12);
      EXPECT_LT((e.point_a - e.point_b - e.depth * e.normal).norm(), 1e-12);
    }
}

TEST(Epa, SegmentInsideBox) {
  // A capsule core pushed into a box: depth of the segment is what EPA sees.
  const SegmentSupport core{Vec3(-0.5, 0, 0.8), Vec3(0.5, 0, 0.8)};
  const BoxSupport box{Vec3(2, 2, 1)};
  const GjkResult g = gjk_distance(core, box, Vec3(0, 0, 1));
  ASSERT_EQ(g.status, GjkStatus::kIntersecting);
  const EpaResult e = epa_penetration(core, box, g.simplex);
  EXPECT_NEAR(e.depth, 0.2, 1e-12);
  EXPECT_TRUE(e.normal.isApprox(Vec3(0, 0, -1), 1e-12));
}

std::vector<Vec3> random_cloud(Random& rng, int count) {
  std::vector<Vec3> points;
  const Vec3 scale = rng.vector(0.2, 1.5);
  for (int i = 0; i < count; ++i)
    points.push_back(rng.vector(-1, 1).cwiseProduct(scale));
  return points;
}

TEST(Epa, RandomHullsAgreeWithSatAndSeparateAlongTheirNormal) {
  Random rng(7);
  int overlapping = 0, separated = 0;
  for (int i = 0; i < 3000; ++i) {
    const auto a = Shape::create(HullDef{random_cloud(rng, rng.integer(4, 64))});
    const auto b = Shape::create(HullDef{random_cloud(rng, rng.integer(4, 64))});
    if (!a || !b) continue;  // a random cloud can be flat; that is tested elsewhere
    Pose pa, pb;
    pa.orientation = rng.rotation();
    pb.orientation = rng.rotation();
    pb.position = rng.direction() * rng.uniform(0, 2.5);
    if (i % 3 == 0) {
      pa.position += Vec3(-1e5, 1e5, 3e4);
      pb.position += Vec3(-1e5, 1e5, 3e4);
    }
    const double size = std::max(a.value().size(), b.value().size());
    CollisionSettings sat, gjk;
    sat.method = NarrowPhaseMethod::kSat;
    gjk.method = NarrowPhaseMethod::kGjkEpa;
    ContactManifold ms, mg;
    const std::uint32_t flags_sat = collide(a.value(), pa, b.value(), pb, sat, &ms);
    const std::uint32_t flags_gjk = collide(a.value(), pa, b.value(), pb, gjk, &mg);
    EXPECT_EQ(flags_sat, 0u);
    ASSERT_EQ(flags_gjk & (kGjkIterationLimit | kEpaIterationLimit), 0u) << i;
    auto deepest = [](const ContactManifold& m) {
      for (int k = 0; k < m.count; ++k) {
        EXPECT_TRUE(m.points[k].point_a.allFinite() && m.points[k].point_b.allFinite());
        EXPECT_LE(m.points[k].depth, m.depth + 1e-12);
      }
      return m.depth;
    };
    ASSERT_EQ(ms.count > 0, mg.count > 0) << "pair " << i;
    if (ms.count == 0) {
      ++separated;
      continue;
    }
    ++overlapping;
    const double depth = deepest(mg);
    ASSERT_NEAR(deepest(ms), depth, 1e-9 * size) << "pair " << i;
    ASSERT_TRUE(mg.normal.allFinite());
    // Moving B by the depth along the normal leaves the pair just touching.
    Pose moved = pb;
    moved.position += depth * mg.normal;
    ContactManifold after;
    collide(a.value(), pa, b.value(), moved, sat, &after);
    const double left = after.count > 0 ? deepest(after) : 0.0;
    ASSERT_NEAR(left, 0.0, 1e-8 * size) << "pair " << i;
  }
  EXPECT_GT(overlapping, 1000);
  EXPECT_GT(separated, 300);
}

// The closed form against a convex search (test_support.h): the squared distance from the box is
// convex along the segment, so a ternary search over the parameter converges on its least value.
TEST(SegmentBox, ClosestMatchesAConvexSearch) {
  Random rng(11);
  int apart = 0, meeting = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vec3 half = rng.vector(0.05, 1.5);
    Vec3 p = rng.vector(-3, 3), q = rng.vector(-3, 3);
    // A segment parallel to a face (or two), and one with an end on a face's plane.
    if (i % 4 == 1) q[rng.integer(0, 2)] = p[0];
    if (i % 4 == 1) q[i % 3] = p[i % 3];
    if (i % 4 == 2) p[rng.integer(0, 2)] = (i % 8 == 2 ? 1 : -1) * half[0];
    auto squared_at = [&](double t) {
      const Vec3 x = p + t * (q - p);
      return (x - x.cwiseMax(-half).cwiseMin(half)).squaredNorm();
    };
    const double reference = testing::segment_box_squared_distance_by_search(p, q, half);
    const SegmentBoxClosest closest = closest_segment_box(p, q, half);
    ASSERT_GE(closest.t, 0.0) << i;
    ASSERT_LE(closest.t, 1.0) << i;
    ASSERT_EQ(closest.squared_distance, squared_at(closest.t)) << i;
    ASSERT_NEAR(closest.squared_distance, reference, 1e-12 * (1 + reference)) << i;
    ASSERT_LE(closest.squared_distance, reference + 1e-14 * (1 + reference)) << i;
    (reference > 1e-12 ? apart : meeting) += 1;
  }
  // Both kinds were met.
  EXPECT_GT(apart, 5000);
  EXPECT_GT(meeting, 1000);
}

// The shortest way out of a box for a segment that entered it, in closed form: through a face, and
// across an edge, against the answers worked by hand; and a non-finite segment still names an axis
// (the answer is not a number, and nothing is read or written out of bounds).
TEST(SegmentBox, PenetrationThroughAFaceAndAcrossAnEdge) {
  const Vec3 half(1, 1, 1);
  // Poking 0.5 m down into the top face: out upwards, its lower end deepest.
  const SegmentBoxPenetration face =
      segment_box_penetration(Vec3(0.2, 0.1, 0.5), Vec3(0.2, 0.1, 2), half, 1e-12);
  EXPECT_NEAR(face.depth, 0.5, 1e-15);
  EXPECT_EQ(face.normal, Vec3(0, 0, -1));
  EXPECT_EQ(face.deepest, Vec3(0.2, 0.1, 0.5));
  // Across the edge x = z = 1 at 45 degrees, through the corner 0.1 / sqrt(2) deep: each face
  // would take 0.4 m.
  const SegmentBoxPenetration edge =
      segment_box_penetration(Vec3(0.6, 0, 1.3), Vec3(1.3, 0, 0.6), half, 1e-12);
  EXPECT_NEAR(edge.depth, 0.1 / std::sqrt(2.0), 1e-15);
  EXPECT_TRUE(edge.normal.isApprox(Vec3(-1, 0, -1).normalized(), 1e-15));
  EXPECT_TRUE(edge.deepest.isApprox(Vec3(0.95, 0, 0.95), 1e-15));
  // Lying 1 cm inside the top face along x: crossed with the y axis it gives the face's own
  // normal and overlap, and the face keeps the tie (its deeper end: the first of two as deep).
  const SegmentBoxPenetration flat =
      segment_box_penetration(Vec3(-0.5, 0.3, 0.99), Vec3(0.5, 0.3, 0.99), half, 1e-12);
  EXPECT_EQ(flat.normal, Vec3(0, 0, -1));
  EXPECT_NEAR(flat.depth, 0.01, 1e-15);
  EXPECT_EQ(flat.deepest, Vec3(-0.5, 0.3, 0.99));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const SegmentBoxPenetration lost =
      segment_box_penetration(Vec3(nan, 0, 0), Vec3(1, 2, 3), half, 0);
  EXPECT_TRUE(std::isnan(lost.depth));
  EXPECT_EQ(lost.normal.squaredNorm(), 1.0);
}

}  // namespace
}  // namespace tumble
