// The snapshot's contact records: a snapshot written before them (impulses point by point, in
// `warm_start`) is still read, its impulses grouped by pair and matched to the points again.
#include <gtest/gtest.h>

#include <set>

#include "scene_runner.h"
#include "snapshot.h"
#include "tumble/v1/snapshot.pb.h"

namespace tumble {
namespace {

server::SavedWorld landed_pile() {
  World world = make_world(pile_scene(20)).value();
  for (int k = 0; k < 40; ++k)
    EXPECT_TRUE(world.step(1.0 / 60).is_ok());
  return server::SavedWorld{world.settings(), world.save_state(), 1.0 / 60, {}, {}, 0, 0};
}

// Rewrites a snapshot's contact records as an older server wrote them.
std::string as_older_snapshot(const std::string& bytes) {
  v1::snapshot::WorldSnapshot snapshot;
  EXPECT_TRUE(snapshot.ParseFromString(bytes));
  const v1::snapshot::ContactPairs& pairs = snapshot.contact_pairs();
  v1::snapshot::WarmStart* old = snapshot.mutable_warm_start();
  int point = 0;
  for (int k = 0; k < pairs.body_a_size(); ++k) {
    for (std::uint32_t i = 0; i < pairs.count(k); ++i, ++point) {
      old->add_body_a(pairs.body_a(k));
      old->add_body_b(pairs.body_b(k));
      old->add_generation_a(pairs.generation_a(k));
      old->add_generation_b(pairs.generation_b(k));
      old->add_feature(pairs.feature(point));
      old->add_normal(pairs.normal_impulse(point));
      for (int c = 0; c < 3; ++c) {
        old->add_local_a(pairs.local_a(3 * point + c));
        old->add_friction(pairs.friction_impulse(3 * point + c));
      }
    }
  }
  snapshot.clear_contact_pairs();
  return snapshot.SerializeAsString();
}

TEST(SnapshotFormat, RecordsRoundTrip) {
  const server::SavedWorld saved = landed_pile();
  ASSERT_FALSE(saved.state.contact_pairs.empty());
  const Result<server::SavedWorld> read = server::decode_snapshot(server::encode_snapshot(saved));
  ASSERT_TRUE(read) << read.error();
  const auto& before = saved.state.contact_pairs;
  const auto& after = read.value().state.contact_pairs;
  ASSERT_EQ(after.size(), before.size());
  for (std::size_t k = 0; k < before.size(); ++k) {
    EXPECT_EQ(after[k].a, before[k].a);
    EXPECT_EQ(after[k].relative_orientation.coeffs(), before[k].relative_orientation.coeffs());
    EXPECT_EQ(after[k].feature_kind, before[k].feature_kind);
    EXPECT_EQ(after[k].feature_first, before[k].feature_first);
    EXPECT_EQ(after[k].colour, before[k].colour);
    ASSERT_EQ(after[k].count, before[k].count);
    for (int i = 0; i < before[k].count; ++i) {
      EXPECT_EQ(after[k].points[i].local_a, before[k].points[i].local_a);
      EXPECT_EQ(after[k].points[i].normal_impulse, before[k].points[i].normal_impulse);
    }
  }
}

// Colours came after the records: a snapshot without them reads as pairs to colour anew; a
// colour that is not one is refused, naming it.
TEST(SnapshotFormat, SnapshotsWithoutColoursReadAndBadColoursAreRefused) {
  const server::SavedWorld saved = landed_pile();
  std::set<std::uint8_t> colours;
  for (const ContactPairRecord& record : saved.state.contact_pairs)
    colours.insert(record.colour);
  ASSERT_GT(colours.size(), 1u);  // so that the round trip above compares something
  v1::snapshot::WorldSnapshot snapshot;
  ASSERT_TRUE(snapshot.ParseFromString(server::encode_snapshot(saved)));
  snapshot.mutable_contact_pairs()->clear_colour();
  const Result<server::SavedWorld> read = server::decode_snapshot(snapshot.SerializeAsString());
  ASSERT_TRUE(read) << read.error();
  for (const ContactPairRecord& record : read.value().state.contact_pairs)
    EXPECT_EQ(record.colour, kNoContactColour);
  Result<World> resumed = World::from_state(saved.settings, read.value().state);
  ASSERT_TRUE(resumed) << resumed.error();
  EXPECT_TRUE(resumed.value().step(saved.dt));

  ASSERT_TRUE(snapshot.ParseFromString(server::encode_snapshot(saved)));
  snapshot.mutable_contact_pairs()->set_colour(1, 300);
  Result<server::SavedWorld> bad = server::decode_snapshot(snapshot.SerializeAsString());
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().find("colour[1]"), std::string::npos) << bad.error();
  snapshot.mutable_contact_pairs()->mutable_colour()->RemoveLast();
  bad = server::decode_snapshot(snapshot.SerializeAsString());
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().find("colour"), std::string::npos) << bad.error();
}

TEST(SnapshotFormat, OlderSnapshotsImpulsesAreMatchedAgain) {
  const server::SavedWorld saved = landed_pile();
  const Result<server::SavedWorld> read =
      server::decode_snapshot(as_older_snapshot(server::encode_snapshot(saved)));
  ASSERT_TRUE(read) << read.error();
  const auto& before = saved.state.contact_pairs;
  const auto& after = read.value().state.contact_pairs;
  ASSERT_EQ(after.size(), before.size());
  for (std::size_t k = 0; k < before.size(); ++k) {
    EXPECT_EQ(after[k].feature_kind, 0);  // not saved then: the narrow phase searches
    ASSERT_EQ(after[k].count, before[k].count);
    for (int i = 0; i < before[k].count; ++i)
      EXPECT_EQ(after[k].points[i].normal_impulse, before[k].points[i].normal_impulse);
  }
  // With the narrow phase run again and the impulses matched to its points by feature, the run
  // goes on as it would have without reuse.
  server::SavedWorld straight = saved;
  straight.settings.solver.manifold_reuse = 0;
  Result<World> expected = World::from_state(straight.settings, straight.state);
  Result<World> resumed = World::from_state(straight.settings, read.value().state);
  ASSERT_TRUE(expected) << expected.error();
  ASSERT_TRUE(resumed) << resumed.error();
  for (int k = 0; k < 30; ++k) {
    ASSERT_TRUE(expected.value().step(saved.dt));
    ASSERT_TRUE(resumed.value().step(saved.dt));
  }
  EXPECT_EQ(testing::state_hash(resumed.value()), testing::state_hash(expected.value()));
}

}  // namespace
}  // namespace tumble
