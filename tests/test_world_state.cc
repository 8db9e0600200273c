// Saving a world and restoring it: the restored world steps on bit for bit; a bad state is
// refused with the field named.
#include <gtest/gtest.h>

#include <cstring>
#include <map>
#include <random>
#include <set>

#include "scene_runner.h"
#include "shape_state.h"
#include "state_format.h"

namespace tumble::testing {
namespace {

// The engine's state as data, through its own bytes both ways: these tests craft states no
// world would save.
WorldStateData data_of(const World& world) {
  return decode_state(world.save_state()).value();
}
Result<World> world_of(const WorldSettings& settings, const WorldStateData& state) {
  return World::from_state(settings, encode_state(state));
}

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

// Damaged bytes are refused with a message, or restore a world that steps within the limits.
// Returns whether they were taken.
bool restored_safely(const WorldSettings& settings, const std::string& bytes) {
  Result<World> restored = World::from_state(settings, bytes);
  if (!restored) {
    EXPECT_FALSE(restored.error().empty());
    return false;
  }
  for (int step = 0; step < 5; ++step)
    EXPECT_TRUE(restored.value().step(kDt));
  for (std::uint32_t slot = 0; slot < restored.value().slot_count(); ++slot) {
    if (const BodyId id = restored.value().id_at(slot); id.is_valid()) {
      EXPECT_TRUE(check_limits(restored.value().body(id), settings.limits));
    }
  }
  return true;
}

// The state is refused, and the message names `field`.
void expect_refused(const WorldSettings& settings, const WorldStateData& state,
                    const std::string& field) {
  Result<World> world = world_of(settings, state);
  ASSERT_FALSE(world) << field;
  EXPECT_NE(world.error().find(field), std::string::npos) << world.error();
}

TEST(WorldState, RestoredWorldStepsOnBitForBit) {
  World original = busy_world();
  const std::string saved = original.save_state();
  ASSERT_FALSE(data_of(original).contact_pairs.empty());
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
  WorldStateData saved = data_of(original);
  saved.contact_pairs.clear();
  World cold = world_of(original.settings(), saved).value();
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
    for (const ContactPairRecord& record : data_of(world).contact_pairs) {
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

  WorldStateData uncoloured = data_of(world);
  for (ContactPairRecord& record : uncoloured.contact_pairs)
    record.colour = kNoContactColour;
  World resumed = world_of(world.settings(), uncoloured).value();
  ASSERT_TRUE(resumed.step(kDt));
  ASSERT_FALSE(data_of(resumed).contact_pairs.empty());
  for (const ContactPairRecord& record : data_of(resumed).contact_pairs)
    EXPECT_LT(record.colour, kContactColours);
}

// A compound pair's records keep their part pairs' features with the parts' indices in the top
// bits: a resumed world clips the same features, and a record naming a part the body lacks, or a
// face its part lacks, is refused.
TEST(WorldState, CompoundRecordsNameTheirParts) {
  SceneDef scene = compound_pile_scene(8);
  scene.world.solver.sleeping = false;
  World world = build(scene);
  for (int k = 0; k < 240; ++k)
    ASSERT_TRUE(world.step(kDt));
  const WorldStateData good = data_of(world);
  std::size_t with_parts = 0, at = 0;
  for (std::size_t k = 0; k < good.contact_pairs.size(); ++k)
    if (good.contact_pairs[k].feature_kind != 0 && good.contact_pairs[k].feature_first >> 16 != 0) {
      ++with_parts;
      at = k;
    }
  ASSERT_GT(with_parts, 0u);  // some part other than the first keeps a feature
  WorldStateData s = good;
  s.contact_pairs[at].feature_first = (200u << 16) | (s.contact_pairs[at].feature_first & 0xffff);
  expect_refused(world.settings(), s, "contact_pairs[" + std::to_string(at) + "].feature");
  s = good;
  s.contact_pairs[at].feature_kind = 1;
  s.contact_pairs[at].feature_first = (s.contact_pairs[at].feature_first & 0xffff0000u) | 1000;
  expect_refused(world.settings(), s, "contact_pairs[" + std::to_string(at) + "].feature");
  World resumed = world_of(world.settings(), good).value();
  std::uint64_t reused = 0;
  for (int k = 0; k < 30; ++k) {
    ASSERT_TRUE(world.step(kDt));
    ASSERT_TRUE(resumed.step(kDt));
    reused += world.last_step().reused_manifolds;
  }
  EXPECT_EQ(resumed.save_state(), world.save_state());
  EXPECT_GT(reused, 0u);  // the part pairs' features were kept, not searched every step
}

TEST(WorldState, BadStatesAreRefusedNamingTheField) {
  const World original = busy_world();
  const WorldStateData good = data_of(original);
  auto refused = [&](const WorldStateData& state, const std::string& field) {
    expect_refused(original.settings(), state, field);
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
  Result<World> world = world_of(bad_settings, good);
  ASSERT_FALSE(world);
  EXPECT_NE(world.error().find("settings.solver.iterations"), std::string::npos);
  bad_settings = original.settings();
  bad_settings.solver.joint_position_passes = 1001;
  world = world_of(bad_settings, good);
  ASSERT_FALSE(world);
  EXPECT_NE(world.error().find("settings.solver.joint_position_passes"), std::string::npos);
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
  ShapeState box{ShapeType::kBox, 0, 0, Vec3(1, -1, 1), nullptr, nullptr, nullptr, nullptr};
  refused(box, "half_extents[1]");
}

// The bytes' header: magic, version, header size, whole length, the three counts, flags.
constexpr std::size_t kVersionAt = 8, kLengthAt = 16, kSlotsAt = 24;

template <class T>
void poke(std::string& bytes, std::size_t at, T value) {
  std::memcpy(bytes.data() + at, &value, sizeof value);
}

TEST(StateFormat, HeaderStatesTheVersionAndTheSizes) {
  const World world = busy_world();
  const std::string bytes = world.save_state();
  ASSERT_EQ(bytes.compare(0, 8, "TUMBLEWS"), 0);
  const StateSizes sizes = World::state_sizes(bytes).value();
  const WorldStateData data = data_of(world);
  EXPECT_EQ(sizes.bytes, bytes.size());
  EXPECT_EQ(sizes.slots, data.slots.size());
  EXPECT_EQ(sizes.free_slots, 2u);
  EXPECT_EQ(sizes.contact_pairs, data.contact_pairs.size());
  // Encoding what was decoded gives the same bytes: nothing is lost or reordered.
  EXPECT_EQ(encode_state(data), bytes);
}

TEST(StateFormat, AnotherVersionIsRefusedNamingBoth) {
  const World world = busy_world();
  for (std::uint32_t version : {0u, World::kStateFormatVersion + 1, 7u}) {
    std::string bytes = world.save_state();
    poke(bytes, kVersionAt, version);
    Result<World> restored = World::from_state(world.settings(), bytes);
    ASSERT_FALSE(restored);
    EXPECT_NE(restored.error().find("format version " + std::to_string(version)), std::string::npos)
        << restored.error();
    EXPECT_NE(restored.error().find("reads version " + std::to_string(World::kStateFormatVersion)),
              std::string::npos)
        << restored.error();
  }
}

TEST(StateFormat, EveryTruncationAndLyingHeaderIsRefused) {
  World world = busy_world();
  const std::string bytes = world.save_state();
  // Cut anywhere (the header's length then disagrees, so fix it too: the body must be checked).
  for (std::size_t n = 0; n < bytes.size(); n += 1 + n / 64) {
    std::string cut = bytes.substr(0, n);
    if (n >= kLengthAt + 8) poke(cut, kLengthAt, std::uint64_t{n});
    EXPECT_FALSE(World::from_state(world.settings(), cut)) << "cut at " << n;
  }
  std::string longer = bytes + "x";
  EXPECT_FALSE(World::from_state(world.settings(), longer));
  poke(longer, kLengthAt, std::uint64_t{longer.size()});
  Result<World> trailing = World::from_state(world.settings(), longer);
  ASSERT_FALSE(trailing);
  EXPECT_NE(trailing.error().find("after the last pair"), std::string::npos) << trailing.error();
  // Counts the bytes cannot hold are refused from the header, before anything is allocated.
  std::string lying = bytes;
  poke(lying, kSlotsAt, std::uint32_t{4000000000u});
  Result<StateSizes> sizes = World::state_sizes(lying);
  ASSERT_FALSE(sizes);
  EXPECT_NE(sizes.error().find("do not fit"), std::string::npos) << sizes.error();
  EXPECT_FALSE(World::from_state(world.settings(), "TUMBLEWS"));
  EXPECT_FALSE(World::from_state(world.settings(), ""));
}

TEST(StateFormat, RestoreStateIsAllOrNothing) {
  World world = busy_world();
  const std::string before = world.save_state();
  const std::uint64_t hash = state_hash(world);
  std::string truncated = before.substr(0, before.size() / 2);
  WorldStateData broken = data_of(world);
  broken.slots[3].body.mass = -1;
  for (const std::string& bytes : {truncated, encode_state(broken), std::string("nonsense")}) {
    EXPECT_FALSE(world.restore_state(bytes));  // each is refused, and leaves the world as it was
    EXPECT_EQ(state_hash(world), hash);
    EXPECT_EQ(world.save_state(), before);
  }
  World other = busy_world();
  run(other, kDt, 30);
  ASSERT_TRUE(world.restore_state(other.save_state()));
  EXPECT_EQ(state_hash(world), state_hash(other));
}

// Random damage to saved bytes never crashes or leaves an unchecked value: every state either is
// refused or steps within the limits (fuzz, as the server's snapshots are fuzzed).
TEST(StateFormat, DamagedBytesAreRefusedOrStepSafely) {
  const World world = busy_world();
  const std::string good = world.save_state();
  std::mt19937_64 random(36);
  int refused = 0, accepted = 0;
  for (int round = 0; round < 400; ++round) {
    std::string bytes = good;
    const int flips = 1 + static_cast<int>(random() % 8);
    for (int k = 0; k < flips; ++k) {
      const std::size_t at = random() % bytes.size();
      switch (random() % 3) {
        case 0:
          bytes[at] = static_cast<char>(random());
          break;
        case 1:
          bytes[at] ^= static_cast<char>(1 << (random() % 8));
          break;
        default:
          bytes.erase(at, 1 + random() % 16);
          break;
      }
    }
    if (restored_safely(world.settings(), bytes))
      ++accepted;
    else
      ++refused;
  }
  EXPECT_GT(refused, 100);
  EXPECT_GT(accepted, 0);  // some flips land on values still valid (a velocity's low bits)
}

// The busy world with a chain of every joint kind hanging from the world beside it, swinging,
// with limits, a motor and springs, and one joint removed (a free joint slot to reuse).
World jointed_world() {
  World world = busy_world();
  BodyDef link;
  link.shape = BoxDef{Vec3(0.2, 0.05, 0.05)};
  BodyId last;
  const JointKind kinds[] = {JointKind::kBall,     JointKind::kHinge, JointKind::kFixed,
                             JointKind::kDistance, JointKind::kBall,  JointKind::kSlider};
  for (int i = 0; i < 6; ++i) {
    link.position = Vec3(6 + 0.4 * i + 0.2, 0, 5);
    const BodyId body = world.create_body(link).value();
    JointDef def;
    def.kind = kinds[i];
    def.a = body;
    def.b = last;
    def.anchor = Vec3(6 + 0.4 * i, 0, 5);
    def.anchor_b = def.anchor - Vec3(0.1, 0, 0);  // a distance joint's rod, 0.1 m
    def.axis = Vec3(0, 1, 0);
    if (def.kind == JointKind::kHinge) {
      def.limit = {true, -0.3, 0.4};
      def.spring = {true, 0.1, 5, 0.5};
    } else if (def.kind == JointKind::kDistance) {
      def.limit = {true, 0.05, 0.12};
    } else if (def.kind == JointKind::kSlider) {
      def.axis = Vec3(1, 0, 0);
      def.limit = {true, -0.05, 0.05};
      def.motor = {true, 0.2, 3};
      def.friction = 0.5;
    } else if (i == 4) {
      def.axis = Vec3(1, 0, 0);
      def.max_swing = 0.5;
      def.limit = {true, -0.2, 0.2};
      def.friction = 0.05;
    }
    EXPECT_TRUE(world.create_joint(def));
    last = body;
  }
  JointDef extra;
  extra.a = last;
  extra.anchor = Vec3(8, 0, 5);
  const JointId removed = world.create_joint(extra).value();
  EXPECT_TRUE(world.remove_joint(removed));
  run(world, kDt, 30);
  return world;
}

TEST(WorldState, JointsAndTheirImpulsesRoundTripBitForBit) {
  World original = jointed_world();
  const std::string saved = original.save_state();
  const WorldStateData data = data_of(original);
  ASSERT_EQ(data.joints.size(), 7u);
  ASSERT_EQ(data.free_joints.size(), 1u);
  Result<World> restored = World::from_state(original.settings(), saved);
  ASSERT_TRUE(restored) << restored.error();
  EXPECT_EQ(restored.value().joint_count(), 6u);
  EXPECT_EQ(restored.value().save_state(), saved);
  run(original, kDt, 90);
  run(restored.value(), kDt, 90);
  EXPECT_EQ(restored.value().save_state(), original.save_state());
  // Without the warm start's impulses the run differs: the test above would see them lost.
  WorldStateData cold = data;
  for (JointSlot& slot : cold.joints) {
    slot.joint.linear_impulse.setZero();
    slot.joint.limit_impulse = slot.joint.motor_impulse = slot.joint.spring_impulse = 0;
    slot.joint.friction_impulse.setZero();
  }
  Result<World> without = world_of(original.settings(), cold);
  ASSERT_TRUE(without) << without.error();
  run(without.value(), kDt, 90);
  EXPECT_NE(without.value().save_state(), original.save_state());
}

TEST(WorldState, BadJointsAreRefusedNamingTheField) {
  const World original = jointed_world();
  const WorldStateData good = data_of(original);
  auto refused = [&](const WorldStateData& state, const std::string& field) {
    expect_refused(original.settings(), state, field);
  };
  WorldStateData s = good;
  s.joints[0].joint.a = static_cast<std::uint32_t>(s.slots.size());  // no such body
  refused(s, "joints[0].a");
  s = good;
  s.slots.push_back({});  // a dead slot, free
  s.free_slots.push_back(static_cast<std::uint32_t>(s.slots.size() - 1));
  s.joints[0].joint.a = static_cast<std::uint32_t>(s.slots.size() - 1);
  refused(s, "joints[0].a");
  s = good;
  s.joints[1].joint.b = 100000;
  refused(s, "joints[1].b");
  s = good;
  s.joints[1].joint.axis_a *= 2;
  refused(s, "joints[1].axis_a");
  s = good;
  s.joints[2].joint.relative.coeffs() *= 3;
  refused(s, "joints[2].relative");
  s = good;
  s.joints[3].joint.length = 0;
  refused(s, "joints[3].length");
  s = good;
  s.joints[4].joint.linear_impulse.x() = std::nan("");
  refused(s, "joints[4].impulses");
  s = good;
  s.free_joints.clear();
  refused(s, "free_joints");
  s = good;
  s.free_joints[0] = 0;  // a live joint
  refused(s, "free_joints[0]");
  s = good;
  s.joints[0].joint.b = s.joints[0].joint.a;
  refused(s, "joints[0].b");
  s = good;
  s.joints[1].joint.limit = {true, 1, -1};
  refused(s, "joints[1].limit");
  s = good;
  s.joints[5].joint.reference_a *= 2;
  refused(s, "joints[5].reference_a");
  s = good;
  s.joints[5].joint.motor.max_force = -1;
  refused(s, "joints[5].motor.max_force");
  s = good;
  s.joints[2].joint.spring = {true, 0, 1, 0};  // a fixed joint
  refused(s, "joints[2].spring");
  s = good;
  s.joints[4].joint.swing_impulse = std::nan("");
  refused(s, "joints[4].impulses");
  s = good;
  s.joints[4].joint.friction_impulse.y() = std::nan("");
  refused(s, "joints[4].impulses");
  s = good;
  s.joints[0].joint.friction = -1;
  refused(s, "joints[0].friction");
  s = good;
  s.joints[2].joint.friction = 1;  // a fixed joint
  refused(s, "joints[2].friction");
}

// Joint friction travels in its own part of each joint (flag 4), written only where a joint has
// some: a world without writes the bytes it wrote before friction existed.
TEST(StateFormat, JointFrictionIsWrittenOnlyWhereThereIsSome) {
  const World with = jointed_world();
  WorldStateData data = data_of(with);
  for (JointSlot& slot : data.joints) {
    slot.joint.friction = 0;
    slot.joint.friction_impulse.setZero();
  }
  const World without = world_of(with.settings(), data).value();
  auto flags = [](const std::string& bytes) {
    std::uint32_t f = 0;
    std::memcpy(&f, bytes.data() + 36, sizeof f);
    return f;
  };
  EXPECT_EQ(flags(with.save_state()), 7u);
  EXPECT_EQ(flags(without.save_state()), 3u);
  EXPECT_EQ(without.save_state().size() + 32 * with.joint_count(), with.save_state().size());
  // Friction without drives is no state this engine writes.
  std::string bytes = with.save_state();
  const std::uint32_t odd = 1 | 4;
  std::memcpy(bytes.data() + 36, &odd, sizeof odd);
  const Result<World> refused = World::from_state(with.settings(), bytes);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().find("flags"), std::string::npos) << refused.error();
}

TEST(StateFormat, DamagedJointBytesAreRefusedOrStepSafely) {
  const World world = jointed_world();
  const std::string good = world.save_state();
  // The joints' section ends the bytes (seven slots of 5 to 365 bytes): damage falls there.
  const std::size_t joints_from = good.size() - 7 * 300;
  std::mt19937_64 random(33);
  int refused = 0;
  for (int round = 0; round < 300; ++round) {
    std::string bytes = good;
    const int flips = 1 + static_cast<int>(random() % 4);
    for (int k = 0; k < flips; ++k) {
      const std::size_t at = joints_from + random() % (bytes.size() - joints_from);
      bytes[at] = static_cast<char>(random());
    }
    if (!restored_safely(world.settings(), bytes)) ++refused;
  }
  EXPECT_GT(refused, 50);
}

// Issue 31 (8): a restored hull must be the hull its vertices make, not whatever was stored.
// Each damage is made in the bytes of a world holding one hull, at the place the format puts it.
TEST(StateFormat, ARestoredHullMustBeTheHullItsVerticesMake) {
  World world;
  BodyDef rock;
  std::vector<Vec3> points;
  for (double x : {-1.0, 1.0})
    for (double y : {-1.0, 1.0})
      for (double z : {-1.0, 1.0})
        points.emplace_back(x * 0.5, y * 0.7, z * 0.9);
  points.emplace_back(0, 0, 1);  // a roof
  rock.shape = HullDef{points};
  ASSERT_TRUE(world.create_body(rock));
  const std::string good = world.save_state();
  const ConvexPolyhedron& hull = *world.body(world.id_at(0)).shape().polyhedron();
  // Header, time, step, generation, alive; then the shape: type, radius, half height, extents.
  const std::size_t vertex_count_at = kStateHeaderBytes + 8 + 8 + 4 + 1 + 1 + 8 + 8 + 24;
  const std::size_t vertices_at = vertex_count_at + 4;
  const std::size_t faces_at = vertices_at + 24 * hull.vertices.size() + 4;
  const std::size_t centroid_at = faces_at + 40 * hull.faces.size() + 4 +
                                  4 * hull.face_vertices.size() + 4 + 16 * hull.edges.size();
  const std::size_t volume_at = centroid_at + 24;
  ASSERT_EQ(good.substr(vertices_at, 8),
            std::string(reinterpret_cast<const char*>(&hull.vertices[0].x()), 8));
  ASSERT_EQ(good.substr(volume_at, 8), std::string(reinterpret_cast<const char*>(&hull.volume), 8));
  struct Damage {
    const char* what;
    std::size_t at;
    double add;
    const char* named;
  };
  const Damage damages[] = {
      {"a vertex 1e4 m off its faces", vertices_at, 1e4, "polyhedron."},
      {"a face offset shifted by 100 m", faces_at + 24, 100, "off its plane"},
      {"a volume of 1e300", volume_at, 1e300, "polyhedron.volume"},
      {"a centroid 1 m away", centroid_at, 1, "polyhedron.centroid"},
  };
  for (const Damage& damage : damages) {
    std::string bytes = good;
    double value;
    std::memcpy(&value, bytes.data() + damage.at, 8);
    value += damage.add;
    std::memcpy(bytes.data() + damage.at, &value, 8);
    Result<World> restored = World::from_state(world.settings(), bytes);
    ASSERT_FALSE(restored) << damage.what;
    EXPECT_NE(restored.error().find(damage.named), std::string::npos)
        << damage.what << ": " << restored.error();
    EXPECT_NE(restored.error().find("slots[0].shape."), std::string::npos) << restored.error();
  }
  // A million more vertices than there are: refused from the count, before any is read.
  std::string bytes = good;
  poke(bytes, vertex_count_at, std::uint32_t{1000000});
  Result<World> many = World::from_state(world.settings(), bytes);
  ASSERT_FALSE(many);
  EXPECT_NE(many.error().find("polyhedron.vertices: 1000000 entries"), std::string::npos)
      << many.error();
  EXPECT_TRUE(World::from_state(world.settings(), good));
}

}  // namespace
}  // namespace tumble::testing
