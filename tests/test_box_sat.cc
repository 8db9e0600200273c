// The separating-axis test's paths for boxes (sat.cc: a box's support by its coordinates' signs,
// and the Gauss-map crossings of two boxes' edges from bitmasks) give the general test's answers
// bit for bit: the same separations, faces, edges and axes, and so the same manifolds and bits of
// every scene. Each pair is measured twice, with the boxes as make_box_polyhedron makes them and
// with copies that do not say they are boxes (the general path).
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "box_pairs.h"
#include "narrow_phase.h"
#include "physics/polyhedron.h"
#include "sat.h"
#include "test_support.h"

namespace tumble {
namespace {

using testing::BoxPair;
using testing::make_box_pair;
using testing::Random;

std::uint64_t bits(double x) {
  return std::bit_cast<std::uint64_t>(x);
}

void expect_same_bits(const Vec3& box_path, const Vec3& general, const std::string& where) {
  for (int k = 0; k < 3; ++k)
    EXPECT_EQ(bits(box_path[k]), bits(general[k])) << where << " coordinate " << k;
}

ConvexPolyhedron general_copy(const ConvexPolyhedron& box) {
  ConvexPolyhedron copy = box;
  copy.box = false;
  return copy;
}

// A rotation of exact zeros and ones (a signed permutation), where coordinates tie exactly.
Mat3 axis_permutation(Random& rng) {
  static const int kOrders[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                    {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  const int* order = kOrders[rng.integer(0, 5)];
  Mat3 m = Mat3::Zero();
  for (int k = 0; k < 3; ++k)
    m(k, order[k]) = rng.integer(0, 1) ? 1.0 : -1.0;
  if (m.determinant() < 0) m.col(0) = -m.col(0);
  return m;
}

struct Tally {
  int edge_axes = 0, face_b_deeper = 0, edges_deeper = 0;
};

void expect_same_answers(const BoxPair& p, const Mat3& rotation_a, const Mat3& rotation_b,
                         const std::string& where, Tally* tally) {
  const ConvexPolyhedron a = make_box_polyhedron(p.ha), b = make_box_polyhedron(p.hb);
  ASSERT_TRUE(a.box && b.box);
  const ConvexPolyhedron general_a = general_copy(a), general_b = general_copy(b);
  const PlacedPolyhedron box_a{&a, rotation_a, p.pa.position};
  const PlacedPolyhedron box_b{&b, rotation_b, p.pb.position};
  const PlacedPolyhedron placed_general_a{&general_a, rotation_a, p.pa.position};
  const PlacedPolyhedron placed_general_b{&general_b, rotation_b, p.pb.position};

  for (const bool a_faces : {true, false}) {
    const FaceQuery fast = a_faces ? query_faces(box_a, box_b) : query_faces(box_b, box_a);
    const FaceQuery slow = a_faces ? query_faces(placed_general_a, placed_general_b)
                                   : query_faces(placed_general_b, placed_general_a);
    EXPECT_EQ(fast.face, slow.face) << where;
    EXPECT_EQ(bits(fast.separation), bits(slow.separation)) << where;
  }
  const EdgeQuery fast = query_edges(box_a, box_b);
  const EdgeQuery slow = query_edges(placed_general_a, placed_general_b);
  EXPECT_EQ(fast.edge_a, slow.edge_a) << where;
  EXPECT_EQ(fast.edge_b, slow.edge_b) << where;
  EXPECT_EQ(bits(fast.separation), bits(slow.separation)) << where;
  expect_same_bits(fast.axis, slow.axis, where + " edge axis");
  if (slow.separation > -std::numeric_limits<double>::infinity()) ++tally->edge_axes;

  // The whole contact, in A's frame as the narrow phase asks for it.
  const Mat3 rotation = rotation_a.transpose() * rotation_b;
  const Vec3 translation = rotation_a.transpose() * (p.pb.position - p.pa.position);
  const double scale = std::max(p.ha.maxCoeff(), p.hb.maxCoeff());
  const CollisionSettings settings;
  ContactManifold box_manifold, general_manifold;
  PolytopeFeature box_feature, general_feature;
  collide_polytopes(a, b, rotation, translation, scale, settings, nullptr, &box_feature,
                    &box_manifold);
  collide_polytopes(general_a, general_b, rotation, translation, scale, settings, nullptr,
                    &general_feature, &general_manifold);
  EXPECT_EQ(box_feature.kind, general_feature.kind) << where;
  EXPECT_EQ(box_feature.first, general_feature.first) << where;
  EXPECT_EQ(box_feature.second, general_feature.second) << where;
  if (general_feature.kind == PolytopeFeature::kFaceB) ++tally->face_b_deeper;
  if (general_feature.kind == PolytopeFeature::kEdges) ++tally->edges_deeper;
  ASSERT_EQ(box_manifold.count, general_manifold.count) << where;
  EXPECT_EQ(bits(box_manifold.depth), bits(general_manifold.depth)) << where;
  expect_same_bits(box_manifold.normal, general_manifold.normal, where + " normal");
  for (int k = 0; k < general_manifold.count; ++k) {
    const ContactPoint &fast_point = box_manifold.points[k],
                       &slow_point = general_manifold.points[k];
    EXPECT_EQ(fast_point.feature_id, slow_point.feature_id) << where << " point " << k;
    EXPECT_EQ(bits(fast_point.depth), bits(slow_point.depth)) << where << " point " << k;
    expect_same_bits(fast_point.point_a, slow_point.point_a, where + " point_a");
    expect_same_bits(fast_point.point_b, slow_point.point_b, where + " point_b");
  }
}

TEST(BoxSat, TheBoxPathsGiveTheGeneralTestsBitsOnTheHardPairs) {
  Random rng(20261130);
  Tally tally;
  for (int i = 0; i < 30000 && !::testing::Test::HasFailure(); ++i) {
    const BoxPair p = make_box_pair(rng, i);
    expect_same_answers(p, p.pa.orientation.toRotationMatrix(), p.pb.orientation.toRotationMatrix(),
                        std::string(p.kind) + " pair " + std::to_string(i), &tally);
  }
  // Edge pairs were measured, and contacts made on B's faces and on edges: every path was taken.
  EXPECT_GT(tally.edge_axes, 15000) << tally.edge_axes;
  EXPECT_GT(tally.face_b_deeper, 2000) << tally.face_b_deeper;
  EXPECT_GT(tally.edges_deeper, 1000) << tally.edges_deeper;
}

// Rotations of exact zeros and ones, and turns of 1e-300 rad from them: coordinates that tie
// exactly, products that are zero, and Gauss-map arcs that meet at their ends.
TEST(BoxSat, TheBoxPathsGiveTheGeneralTestsBitsWhereCoordinatesTie) {
  Random rng(7);
  Tally tally;
  for (int i = 0; i < 20000 && !::testing::Test::HasFailure(); ++i) {
    BoxPair p = make_box_pair(rng, 0);
    Mat3 rotation_a = axis_permutation(rng), rotation_b = axis_permutation(rng);
    if (i % 3 == 1)
      rotation_b = rotation_b * Eigen::AngleAxisd(1e-300, rng.direction()).toRotationMatrix();
    if (i % 3 == 2)
      rotation_b =
          rotation_b *
          Eigen::AngleAxisd(rng.uniform(-1, 1), Vec3::Unit(rng.integer(0, 2))).toRotationMatrix();
    // Centres on a grid, so that offsets along the axes tie too.
    p.pa.position = Vec3::Zero();
    p.pb.position = Vec3(rng.integer(-4, 4), rng.integer(-4, 4), rng.integer(-4, 4)) * 0.5;
    expect_same_answers(p, rotation_a, rotation_b, "tied pair " + std::to_string(i), &tally);
  }
  EXPECT_GT(tally.edge_axes, 5000) << tally.edge_axes;
}

// Boxes all but concentric, turned every way: each pair of crossing edges and its opposite
// separate by nearly the same amount (twice the centres' offset along their axis, 1e-17 to
// 1e-8 m), so rounding decides which is the first largest, and the box path must measure the
// same pairs in the same order to name the same one.
TEST(BoxSat, TheBoxPathsGiveTheGeneralTestsBitsForAlmostConcentricBoxes) {
  Random rng(11);
  Tally tally;
  for (int i = 0; i < 20000 && !::testing::Test::HasFailure(); ++i) {
    BoxPair p = make_box_pair(rng, 0);
    p.pa.position = Vec3::Zero();
    p.pb.position = rng.direction() * std::pow(10.0, rng.uniform(-17, -8));
    // Every other pair nearly aligned (edges 1e-12 to 1e-3 rad from parallel), where an axis's
    // normalisation magnifies the separations' rounding.
    if (i % 2 == 1) p.pb.orientation = p.pa.orientation * testing::small_rotation(rng);
    expect_same_answers(p, p.pa.orientation.toRotationMatrix(), p.pb.orientation.toRotationMatrix(),
                        "concentric pair " + std::to_string(i), &tally);
  }
  EXPECT_GT(tally.edge_axes, 15000) << tally.edge_axes;
}

}  // namespace
}  // namespace tumble
