// The server's snapshot: the engine's own bytes for the world (World::save_state) wrapped with
// the server's settings, step, ids and colours. Snapshots of version 1, which copied the engine's
// layout field by field, are refused naming both versions.
#include <gtest/gtest.h>

#include "scene_runner.h"
#include "snapshot.h"
#include "tumble/v1/snapshot.pb.h"

namespace tumble {
namespace {

server::SavedWorld landed_pile() {
  World world = make_world(pile_scene(20)).value();
  for (int k = 0; k < 40; ++k)
    EXPECT_TRUE(world.step(1.0 / 60).is_ok());
  server::SavedWorld saved;
  saved.settings = world.settings();
  saved.state = world.save_state();
  saved.dt = 1.0 / 60;
  for (std::uint32_t slot = 0; slot < world.slot_count(); ++slot) {
    saved.ids.push_back(world.id_at(slot).is_valid() ? 100 + slot : 0);
    saved.colours.push_back(0x11223300u + slot);
  }
  saved.next_id = 100 + world.slot_count();
  saved.server_instance = 0xfeedu;
  return saved;
}

v1::snapshot::WorldSnapshot parsed(const std::string& bytes) {
  v1::snapshot::WorldSnapshot snapshot;
  EXPECT_TRUE(snapshot.ParseFromString(bytes));
  return snapshot;
}

std::string refusal(const v1::snapshot::WorldSnapshot& snapshot) {
  Result<server::SavedWorld> read = server::decode_snapshot(snapshot.SerializeAsString());
  return read ? std::string() : read.error();
}

TEST(SnapshotFormat, WrapsTheEnginesBytesAndRoundTrips) {
  const server::SavedWorld saved = landed_pile();
  ASSERT_GT(World::state_sizes(saved.state).value().contact_pairs, 0u);
  const Result<server::SavedWorld> read = server::decode_snapshot(server::encode_snapshot(saved));
  ASSERT_TRUE(read) << read.error();
  EXPECT_EQ(read.value().state, saved.state);  // the engine's bytes, untouched
  EXPECT_EQ(read.value().ids, saved.ids);
  EXPECT_EQ(read.value().colours, saved.colours);
  EXPECT_EQ(read.value().next_id, saved.next_id);
  EXPECT_EQ(read.value().server_instance, saved.server_instance);
  EXPECT_EQ(read.value().dt, saved.dt);
  EXPECT_EQ(parsed(server::encode_snapshot(saved)).version(), v1::snapshot::VERSION_2);

  World expected = World::from_state(saved.settings, saved.state).value();
  World resumed = World::from_state(read.value().settings, read.value().state).value();
  for (int k = 0; k < 30; ++k) {
    ASSERT_TRUE(expected.step(saved.dt));
    ASSERT_TRUE(resumed.step(saved.dt));
  }
  EXPECT_EQ(testing::state_hash(resumed), testing::state_hash(expected));
}

TEST(SnapshotFormat, TheJointPassesRoundTripAndASnapshotWithoutThemTakesTheDefault) {
  server::SavedWorld saved = landed_pile();
  saved.settings.solver.joint_position_passes = 1;
  const Result<server::SavedWorld> read = server::decode_snapshot(server::encode_snapshot(saved));
  ASSERT_TRUE(read) << read.error();
  EXPECT_EQ(read.value().settings.solver.joint_position_passes, 1);
  // Written before the field existed: absent, not 0 (which would turn the passes off).
  v1::snapshot::WorldSnapshot older = parsed(server::encode_snapshot(saved));
  older.mutable_settings()->mutable_solver()->clear_joint_position_passes();
  const Result<server::SavedWorld> old_read = server::decode_snapshot(older.SerializeAsString());
  ASSERT_TRUE(old_read) << old_read.error();
  EXPECT_EQ(old_read.value().settings.solver.joint_position_passes,
            SolverSettings{}.joint_position_passes);
}

TEST(SnapshotFormat, OtherVersionsAreRefusedNamingBoth) {
  v1::snapshot::WorldSnapshot old = parsed(server::encode_snapshot(landed_pile()));
  old.set_version(v1::snapshot::VERSION_1);
  old.clear_engine_state();  // a version 1 snapshot held its bodies in fields now reserved
  const std::string message = refusal(old);
  EXPECT_NE(message.find("version: 1"), std::string::npos) << message;
  EXPECT_NE(message.find("reads version 2"), std::string::npos) << message;

  v1::snapshot::WorldSnapshot newer = parsed(server::encode_snapshot(landed_pile()));
  newer.set_version(static_cast<v1::snapshot::Version>(3));
  EXPECT_NE(refusal(newer).find("version: 3"), std::string::npos) << refusal(newer);

  // The engine's own version, inside, is checked by the engine, and named as the engine's.
  v1::snapshot::WorldSnapshot engine = parsed(server::encode_snapshot(landed_pile()));
  engine.mutable_engine_state()->at(8) = 9;  // the engine's format version, little-endian
  const std::string inner = refusal(engine);
  EXPECT_NE(inner.find("engine_state.version: format version 9"), std::string::npos) << inner;
}

TEST(SnapshotFormat, TheServersOwnFieldsAreCheckedAgainstTheEngineState) {
  const v1::snapshot::WorldSnapshot good = parsed(server::encode_snapshot(landed_pile()));
  v1::snapshot::WorldSnapshot s = good;
  s.mutable_ids()->RemoveLast();
  EXPECT_NE(refusal(s).find("the engine state has"), std::string::npos) << refusal(s);
  s = good;
  s.add_colors(0);
  EXPECT_NE(refusal(s).find("the engine state has"), std::string::npos) << refusal(s);
  s = good;
  s.set_ids(3, s.ids(2));
  EXPECT_NE(refusal(s).find("ids[3]: used by another slot too"), std::string::npos) << refusal(s);
  s = good;
  s.set_ids(1, std::uint64_t{1} << 60);
  EXPECT_NE(refusal(s).find("ids[1]: must be below 2^53"), std::string::npos) << refusal(s);
  s = good;
  s.set_next_id(UINT64_MAX);
  EXPECT_NE(refusal(s).find("next_id"), std::string::npos) << refusal(s);
  s = good;
  s.set_dt(-1);
  EXPECT_NE(refusal(s).find("dt"), std::string::npos) << refusal(s);
  s = good;
  s.mutable_engine_state()->resize(100);
  EXPECT_NE(refusal(s).find("engine_state.length"), std::string::npos) << refusal(s);
  EXPECT_EQ(refusal(good), "");
}

}  // namespace
}  // namespace tumble
