// Contact pair records (contact_pairs.h): pairs find their records in one walk, a known feature
// gives the manifold the search would, the motion bound covers the points where the pair can
// touch, and a world keeps features only of pairs that barely moved.
#include <gtest/gtest.h>

#include "contact_pairs.h"
#include "physics/world.h"
#include "test_support.h"

namespace tumble {
namespace {

using testing::Random;

Shape random_shape(Random& rng, int kind) {
  switch (kind) {
    case 0:
      return Shape::create(BoxDef{rng.vector(0.1, 2.0)}).value();
    case 1:
      return Shape::create(SphereDef{rng.uniform(0.1, 1.0)}).value();
    case 2:
      return Shape::create(CapsuleDef{rng.uniform(0.1, 0.5), rng.uniform(0.1, 1.0)}).value();
    default: {
      HullDef hull;
      for (int i = 0; i < 12; ++i)
        hull.points.push_back(rng.vector(-1, 1));
      return Shape::create(hull).value();
    }
  }
}

// This step's pairs find last step's records in one walk over both sorted lists: each pair gets the
// record of its two slots, or none, as a search of every record would say.
TEST(ContactPairs, PairsMatchTheirRecordsInOneWalk) {
  Random rng(3);
  for (int round = 0; round < 50; ++round) {
    std::vector<BodyPair> pairs;
    std::vector<ContactPairRecord> records;
    for (std::uint32_t a = 0; a < 40; ++a)
      for (std::uint32_t b = a + 1; b < 40; ++b) {
        if (rng.uniform() < 0.1) pairs.push_back({a, b});
        if (rng.uniform() < 0.1) {
          ContactPairRecord record;
          record.a = {a, 0};
          record.b = {b, 0};
          records.push_back(record);
        }
      }
    std::vector<std::uint32_t> matched(pairs.size(), 12345);
    match_pair_records(pairs, records, matched);
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      std::uint32_t expected = kNoRecord;
      for (std::size_t r = 0; r < records.size(); ++r)
        if (records[r].a.index == pairs[i].a && records[r].b.index == pairs[i].b)
          expected = static_cast<std::uint32_t>(r);
      ASSERT_EQ(matched[i], expected) << "round " << round << ", pair " << i;
    }
  }
}

// Boxes and hulls: the feature the search chose, given back at the same poses, gives the same
// manifold bit for bit; after a small motion, the manifold of the same feature measured again.
TEST(ContactPairs, KnownFeatureGivesTheSearchedManifold) {
  Random rng(7);
  int same = 0, moved = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const Shape a = random_shape(rng, trial % 2 == 0 ? 0 : 3);
    const Shape b = random_shape(rng, (trial / 2) % 2 == 0 ? 0 : 3);
    Pose pose_a{rng.vector(-5, 5), rng.rotation()};
    Pose pose_b{
        pose_a.position + rng.direction() * rng.uniform(0, a.outer_radius() + b.outer_radius()),
        rng.rotation()};
    CollisionSettings settings;
    settings.margin = 0.05;
    ContactManifold found;
    PolytopeFeature chosen;
    collide(a, pose_a, b, pose_b, settings, nullptr, &chosen, &found);
    if (found.count == 0 || chosen.kind == PolytopeFeature::kNone) continue;
    EXPECT_TRUE(chosen.searched);
    ASSERT_TRUE(feature_fits(a, b, chosen));
    ContactManifold again;
    PolytopeFeature kept;
    collide(a, pose_a, b, pose_b, settings, &chosen, &kept, &again);
    EXPECT_FALSE(kept.searched);
    EXPECT_EQ(kept.kind, chosen.kind);
    ASSERT_EQ(again.count, found.count) << "trial " << trial;
    for (int i = 0; i < found.count; ++i) {
      EXPECT_EQ(again.points[i].point_a, found.points[i].point_a);
      EXPECT_EQ(again.points[i].point_b, found.points[i].point_b);
      EXPECT_EQ(again.points[i].depth, found.points[i].depth);
    }
    EXPECT_EQ(again.normal, found.normal);
    // The pair's depth is the chosen feature's, within the slack that chose it.
    EXPECT_NEAR(again.depth, found.depth, 1e-9 * (1 + found.depth));
    ++same;

    // B nudged: when the search still picks the same feature, the known feature's manifold is
    // the search's.
    const Pose nudged{pose_b.position + rng.direction() * 1e-4,
                      Quat(Eigen::AngleAxisd(1e-4, rng.direction())) * pose_b.orientation};
    ContactManifold searched, known;
    PolytopeFeature searched_feature;
    collide(a, pose_a, b, nudged, settings, nullptr, &searched_feature, &searched);
    if (searched_feature.kind != chosen.kind || searched_feature.first != chosen.first ||
        searched_feature.second != chosen.second)
      continue;
    collide(a, pose_a, b, nudged, settings, &chosen, nullptr, &known);
    ASSERT_EQ(known.count, searched.count);
    for (int i = 0; i < known.count; ++i) {
      EXPECT_EQ(known.points[i].point_b, searched.points[i].point_b);
      EXPECT_EQ(known.points[i].depth, searched.points[i].depth);
    }
    ++moved;
  }
  EXPECT_GT(same, 1500);
  EXPECT_GT(moved, 1000);
}

TEST(ContactPairs, MotionBoundCoversThePointsThatCanTouchAndIgnoresMovingTogether) {
  Random rng(11);
  int points_checked = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Shape a = random_shape(rng, trial % 4), b = random_shape(rng, (trial / 4) % 4);
    Pose pose_a{rng.vector(-1, 1), rng.rotation()}, pose_b{rng.vector(-1, 1), rng.rotation()};
    ContactPairRecord record;
    record_manifold(ContactManifold{}, PolytopeFeature{}, {0, 1}, pose_a, {1, 1}, pose_b, &record);

    // Both moved by one rigid motion: nothing moved relative to the other.
    const Pose common{rng.vector(-1, 1), rng.rotation()};
    const Pose moved_a{common.transform(pose_a.position), common.orientation * pose_a.orientation};
    const Pose moved_b{common.transform(pose_b.position), common.orientation * pose_b.orientation};
    EXPECT_NEAR(relative_motion(record, moved_a, moved_b, a.outer_radius(), b.outer_radius()), 0,
                1e-9);

    // B alone nudged: its surface points that can touch A (within A's outer sphere) moved in A's
    // axes by at most the bound.
    const double angle = std::pow(10.0, rng.uniform(-7, -2));
    Pose nudged_b{pose_b.position + rng.direction() * std::pow(10.0, rng.uniform(-7, -2)),
                  Quat(Eigen::AngleAxisd(angle, rng.direction())) * pose_b.orientation};
    const double bound =
        relative_motion(record, pose_a, nudged_b, a.outer_radius(), b.outer_radius());
    for (int k = 0; k < 40; ++k) {
      const Vec3 on_b = b.support(rng.direction());
      if ((pose_b.transform(on_b) - pose_a.position).norm() > a.outer_radius()) continue;
      const Vec3 before = pose_a.inverse_transform(pose_b.transform(on_b));
      const Vec3 after = pose_a.inverse_transform(nudged_b.transform(on_b));
      EXPECT_LE((after - before).norm(), bound * (1 + 1e-9) + 1e-12);
      ++points_checked;
    }
    EXPECT_GT(bound, 0);
  }
  EXPECT_GT(points_checked, 20000);
}

// A box resting on another keeps its feature; a sliding one and a moved one are searched again.
TEST(ContactPairs, WorldKeepsFeaturesOnlyOfPairsThatBarelyMoved) {
  WorldSettings settings;
  settings.solver.sleeping = false;
  World world(settings);
  BodyDef ground;  // a box, so that its pairs are polytope pairs
  ground.type = BodyType::kStatic;
  ground.shape = BoxDef{Vec3(20, 20, 0.5)};
  ground.position = Vec3(0, 0, -0.5);
  ASSERT_TRUE(world.create_body(ground));
  BodyDef box;
  box.shape = BoxDef{Vec3(0.5, 0.5, 0.5)};
  box.position = Vec3(0, 0, 0.5);
  const BodyId resting = world.create_body(box).value();
  box.position = Vec3(5, 0, 0.5);
  box.linear_velocity = Vec3(3, 0, 0);
  box.friction = 0.1;
  ASSERT_TRUE(world.create_body(box));
  for (int k = 0; k < 30; ++k)
    ASSERT_TRUE(world.step(1.0 / 60));
  EXPECT_EQ(world.last_step().manifolds, 2u);
  EXPECT_EQ(world.last_step().reused_manifolds, 1u);  // the resting box's

  BodyMotion moved;
  moved.position = Vec3(0, 0.001, 0.5);
  ASSERT_TRUE(world.set_motion(resting, moved));
  ASSERT_TRUE(world.step(1.0 / 60));
  EXPECT_EQ(world.last_step().reused_manifolds, 0u);

  WorldSettings off = world.settings();
  off.solver.manifold_reuse = 0;
  ASSERT_TRUE(world.set_settings(off));
  for (int k = 0; k < 10; ++k) {
    ASSERT_TRUE(world.step(1.0 / 60));
    EXPECT_EQ(world.last_step().reused_manifolds, 0u);
  }
}

}  // namespace
}  // namespace tumble
