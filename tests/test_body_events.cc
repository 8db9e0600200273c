// The world's body events: what changed since they were last cleared, so that a mirror of the
// world (the server's frames) touches only those bodies.
#include <gtest/gtest.h>

#include <map>

#include "scene_runner.h"

namespace tumble::testing {
namespace {

constexpr double kDt = 1.0 / 60;

std::map<BodyId, std::uint8_t> events_of(const World& world) {
  std::map<BodyId, std::uint8_t> events;
  for (const BodyEvent& event : world.body_events()) {
    EXPECT_FALSE(events.contains(event.body)) << "listed twice";
    events[event.body] = event.flags;
  }
  return events;
}

// Boxes on the ground, asleep, and the ground's id.
World resting_boxes(int count, BodyId* ground) {
  World world;
  BodyDef floor;
  floor.shape = HalfSpaceDef{};
  floor.type = BodyType::kStatic;
  *ground = world.create_body(floor).value();
  for (int i = 0; i < count; ++i) {
    BodyDef box;
    box.shape = BoxDef{Vec3(0.5, 0.5, 0.5)};
    box.position = Vec3(2.0 * (i % 10), 2.0 * (i / 10), 0.5);
    EXPECT_TRUE(world.create_body(box));
  }
  run(world, kDt, 120);
  EXPECT_EQ(world.last_step().sleeping_bodies, static_cast<std::uint32_t>(count));
  return world;
}

TEST(BodyEvents, ListWhatWasMadeMovedAndFellAsleep) {
  World world;
  BodyDef box;
  box.position = Vec3(0, 0, 5);
  const BodyId a = world.create_body(box).value();
  std::map<BodyId, std::uint8_t> events = events_of(world);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[a], kBodyAdded);
  ASSERT_TRUE(world.step(kDt));
  EXPECT_EQ(events_of(world)[a], kBodyAdded | kBodyMoved);
  world.clear_body_events();
  EXPECT_TRUE(world.body_events().empty());
  ASSERT_TRUE(world.step(kDt));
  EXPECT_EQ(events_of(world)[a], kBodyMoved);
}

TEST(BodyEvents, ASleepingWorldListsOnlyWhatChanges) {
  BodyId ground;
  World world = resting_boxes(50, &ground);
  std::map<BodyId, std::uint8_t> asleep = events_of(world);
  ASSERT_EQ(asleep.size(), 51u);
  EXPECT_EQ(asleep[ground], kBodyAdded);
  EXPECT_EQ(asleep[world.id_at(7)], kBodyAdded | kBodyMoved | kBodyFellAsleep);
  world.clear_body_events();
  run(world, kDt, 10);
  EXPECT_TRUE(world.body_events().empty()) << world.body_events().size() << " events";

  BodyDef falling;
  falling.shape = SphereDef{0.25};
  falling.position = Vec3(50, 50, 10);  // far from the boxes
  const BodyId ball = world.create_body(falling).value();
  run(world, kDt, 10);
  std::map<BodyId, std::uint8_t> events = events_of(world);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[ball], kBodyAdded | kBodyMoved);

  // An impulse wakes a box (and only its own island: each box rests alone on the ground).
  world.clear_body_events();
  const BodyId box = world.id_at(3);
  ASSERT_TRUE(world.apply_impulse(box, Vec3(0, 0, 1), nullptr));
  events = events_of(world);
  EXPECT_EQ(events[box], kBodyWoke | kBodyMoved);
  // A static body moved is listed although no step moves it; a removed one is listed as such.
  world.clear_body_events();
  BodyMotion lower;
  lower.position = Vec3(0, 0, -0.001);
  ASSERT_TRUE(world.set_motion(ground, lower));
  ASSERT_TRUE(world.remove_body(ball));
  events = events_of(world);
  EXPECT_EQ(events[ground], kBodyMoved);
  EXPECT_EQ(events[ball], kBodyRemoved);
}

TEST(BodyEvents, AreBoundedAndSayWhenIncomplete) {
  BodyId ground;
  World world = resting_boxes(4, &ground);
  world.clear_body_events();
  BodyDef box;
  box.position = Vec3(0, 0, 9);
  // The same slot made and removed over and over: one entry each time, up to the bound.
  for (int i = 0; i < 10000; ++i)
    ASSERT_TRUE(world.remove_body(world.create_body(box).value()));
  EXPECT_FALSE(world.body_events_complete());
  EXPECT_LE(world.body_events().size(), 2 * world.slot_count() + 4096);
  world.clear_body_events();
  EXPECT_TRUE(world.body_events_complete());
  EXPECT_TRUE(world.body_events().empty());

  // A world made from saved bytes is new to every mirror.
  World restored = World::from_state(world.settings(), world.save_state()).value();
  EXPECT_FALSE(restored.body_events_complete());
}

}  // namespace
}  // namespace tumble::testing
