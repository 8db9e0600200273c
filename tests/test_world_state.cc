// Saving a world and restoring it: the restored world steps on bit for bit; a bad state is
// refused with the field named.
#include <gtest/gtest.h>

#include <map>
#include <set>

#include "scene_runner.h"

namespace tumble::testing {
namespace {

// The default scene plus a tetrahedral hull (an off-centre centroid, so the stored polyhedron is
// the re-centred one) and two removed bodies (free slots to reuse).
World busy_world() {
  SceneDef scene = standard_scene("default").value();
  BodyDef hull;
  hull.shape = HullDef{{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)}};
  hull.position = Vec3(0.3, 0.2, 4);
  scene.bodies.push_back(hull);
  World world = build(scene);
  run(world, scene.dt, 40);
  EXPECT_TRUE(world.remove_body(world.id_at(5)));
  EXPECT_TRUE(world.remove_body(world.id_at(9)));
  run(world, scene.dt, 20);
  return world;
}

constexpr double kDt = 1.0 / 60;

TEST(WorldState, RestoredWorldStepsOnBitForBit) {
  World original = busy_world();
  const WorldStateData saved = original.save_state();
  ASSERT_FALSE(saved.contact_pairs.empty());
  Result<World> restored = World::from_state(original.settings(), saved);
  ASSERT_TRUE(restored) << restored.error();
  EXPECT_EQ(restored.value().step_count(), original.step_count());
  EXPECT_EQ(restored.value().time(), original.time());
  EXPECT_EQ(state_hash(restored.value()), state_hash(original));

  // New bodies take the same slots and ids in both.
  BodyDef box;
  box.position = Vec3(0, 0, 6);
  const BodyId a = original.create_body(box).value();
  const BodyId b = restored.value().create_body(box).value();
  EXPECT_EQ(a, b);
  run(original, kDt, 90);
  run(restored.value(), kDt, 90);
  EXPECT_EQ(state_hash(restored.value()), state_hash(original));
  EXPECT_EQ(restored.value().step_count(), original.step_count());
}

// Shows the test above would catch lost contact pair records (impulses, reused manifolds):
// without them the run differs.
TEST(WorldState, WarmStartCacheChangesTheRun) {
  World original = busy_world();
  WorldStateData saved = original.save_state();
  saved.contact_pairs.clear();
  World cold = World::from_state(original.settings(), std::move(saved)).value();
  run(original, kDt, 30);
  run(cold, kDt, 30);
  EXPECT_NE(state_hash(cold), state_hash(original));
}

// A touching pair keeps the solver's colour it was given when it started touching (the record
// carries it); a state without colours (an older snapshot's) steps on and colours its pairs anew.
TEST(WorldState, TouchingPairsKeepTheirColoursFromStepToStep) {
  World world = busy_world();
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint8_t> last;
  std::size_t kept = 0;
  std::set<std::uint8_t> seen;
  for (int step = 0; step < 60; ++step) {
    ASSERT_TRUE(world.step(kDt));
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint8_t> now;
    for (const ContactPairRecord& record : world.save_state().contact_pairs) {
      ASSERT_LT(record.colour, kContactColours);
      now[{record.a.index, record.b.index}] = record.colour;
      seen.insert(record.colour);
      const auto before = last.find({record.a.index, record.b.index});
      if (before == last.end()) continue;
      EXPECT_EQ(record.colour, before->second) << "step " << step;
      ++kept;
    }
    last = std::move(now);
  }
  EXPECT_GT(kept, 1000u);
  EXPECT_GT(seen.size(), 3u);

  WorldStateData uncoloured = world.save_state();
  for (ContactPairRecord& record : uncoloured.contact_pairs)
    record.colour = kNoContactColour;
  World resumed = World::from_state(world.settings(), std::move(uncoloured)).value();
  ASSERT_TRUE(resumed.step(kDt));
  ASSERT_FALSE(resumed.save_state().contact_pairs.empty());
  for (const ContactPairRecord& record : resumed.save_state().contact_pairs)
    EXPECT_LT(record.colour, kContactColours);
}

TEST(WorldState, BadStatesAreRefusedNamingTheField) {
  const World original = busy_world();
  const WorldStateData good = original.save_state();
  auto refused = [&](WorldStateData state, const std::string& field) {
    Result<World> world = World::from_state(original.settings(), std::move(state));
    ASSERT_FALSE(world) << field;
    EXPECT_NE(world.error().find(field), std::string::npos) << world.error();
  };
  WorldStateData s = good;
  s.slots[2].body.position.x() = std::nan("");
  refused(s, "slots[2].position");
  s = good;
  s.slots[2].body.orientation.coeffs() *= 2;
  refused(s, "slots[2].orientation");
  s = good;
  s.slots[3].body.mass = -1;
  refused(s, "slots[3].mass");
  s = good;
  s.slots[3].body.sleep_island = 100000;
  refused(s, "slots[3].sleep_island");
  s = good;
  s.free_slots.pop_back();
  refused(s, "free_slots");
  s = good;
  s.free_slots.push_back(1);  // alive
  refused(s, "free_slots[2]");
  s = good;
  std::swap(s.contact_pairs.front(), s.contact_pairs.back());
  refused(s, "not sorted");
  s = good;
  s.contact_pairs[0].b.index = 1u << 30;
  refused(s, "contact_pairs[0]");
  s = good;
  s.contact_pairs[1].feature_kind = 1;
  s.contact_pairs[1].feature_first = 1000;  // a box has 6 faces
  refused(s, "contact_pairs[1].feature");
  s = good;
  s.contact_pairs[1].count = 5;
  refused(s, "contact_pairs[1].count");
  s = good;
  s.contact_pairs[1].colour = kContactColours;
  refused(s, "contact_pairs[1].colour");
  s = good;
  s.time = -1;
  refused(s, "time");
  WorldSettings bad_settings = original.settings();
  bad_settings.solver.iterations = 0;
  Result<World> world = World::from_state(bad_settings, good);
  ASSERT_FALSE(world);
  EXPECT_NE(world.error().find("settings.solver.iterations"), std::string::npos);
}

TEST(WorldState, ShapeStateRoundTripsAndBadPolyhedraAreRefused) {
  const Shape hull =
      Shape::create(HullDef{{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)}})
          .value()
          .recentred(Vec3(0.25, 0.25, 0.25));
  const Shape copy = Shape::from_state(hull.state()).value();
  EXPECT_EQ(copy.inner_radius(), hull.inner_radius());
  EXPECT_EQ(copy.outer_radius(), hull.outer_radius());
  EXPECT_EQ(copy.half_extents(), hull.half_extents());
  EXPECT_EQ(copy.polyhedron()->vertices, hull.polyhedron()->vertices);
  for (const ShapeDef& def : {ShapeDef(SphereDef{0.3}), ShapeDef(CapsuleDef{0.2, 0.7}),
                              ShapeDef(BoxDef{Vec3(0.1, 0.2, 0.3)}), ShapeDef(HalfSpaceDef{})}) {
    const Shape shape = Shape::create(def).value();
    const Shape back = Shape::from_state(shape.state()).value();
    EXPECT_EQ(back.type(), shape.type());
    EXPECT_EQ(back.radius(), shape.radius());
    EXPECT_EQ(back.half_height(), shape.half_height());
    EXPECT_EQ(back.half_extents(), shape.half_extents());
  }

  auto refused = [](const ShapeState& state, const std::string& field) {
    Result<Shape> shape = Shape::from_state(state);
    ASSERT_FALSE(shape) << field;
    EXPECT_NE(shape.error().find(field), std::string::npos) << shape.error();
  };
  ShapeState state = hull.state();
  auto broken = std::make_shared<ConvexPolyhedron>(*hull.polyhedron());
  broken->face_vertices[2] = 99;
  state.polyhedron = broken;
  refused(state, "face_vertices[2]");
  broken = std::make_shared<ConvexPolyhedron>(*hull.polyhedron());
  broken->faces[1].count = 1000;
  state.polyhedron = broken;
  refused(state, "faces[1]");
  broken = std::make_shared<ConvexPolyhedron>(*hull.polyhedron());
  broken->edges[0].left = 77;
  state.polyhedron = broken;
  refused(state, "edges[0]");
  state.polyhedron = nullptr;
  refused(state, "polyhedron");
  ShapeState box{ShapeType::kBox, 0, 0, Vec3(1, -1, 1), nullptr};
  refused(box, "half_extents[1]");
}

}  // namespace
}  // namespace tumble::testing
