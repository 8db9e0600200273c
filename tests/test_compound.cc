// Compound shapes: refusals that name the part; mass properties against their closed forms; a
// table of five boxes standing on its legs on the ground, on a heightfield and on a mesh, each
// leg with its own manifold; two compounds meeting part to part; rays and overlaps that see the
// parts and not the gaps between them; the manifold bound; snapshots bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "physics/collision.h"
#include "physics/compound.h"
#include "physics/world.h"
#include "terrain_support.h"

namespace tumble {
namespace {

using namespace terrain_testing;

CompoundPart part(const ShapeDef& shape, const Vec3& at,
                  const Quat& orientation = Quat::Identity()) {
  return {shape, Pose{at, orientation}};
}

// A 1.2 x 0.8 m top 0.1 m thick on four 0.1 m square legs 0.7 m long: its frame's origin at the
// floor under its middle, so it stands where it is put.
CompoundDef table() {
  CompoundDef def;
  def.parts.push_back(part(BoxDef::of_size(Vec3(1.2, 0.8, 0.1)), Vec3(0, 0, 0.75)));
  for (double x : {-0.55, 0.55})
    for (double y : {-0.35, 0.35})
      def.parts.push_back(part(BoxDef::of_size(Vec3(0.1, 0.1, 0.7)), Vec3(x, y, 0.35)));
  return def;
}

// The manifolds of the awake and of those asleep.
std::vector<Contact> every_contact(const World& world) {
  std::vector<Contact> all(world.contacts().begin(), world.contacts().end());
  all.insert(all.end(), world.resting_contacts().begin(), world.resting_contacts().end());
  return all;
}

std::string refusal(const ShapeDef& def) {
  const Result<Shape> shape = Shape::create(def);
  return shape ? "" : shape.status().message();
}

TEST(Compound, RefusesBadDefinitionsNamingThePart) {
  EXPECT_EQ(refusal(table()), "");
  EXPECT_EQ(refusal(CompoundDef{}), "parts: a compound needs at least one part");
  CompoundDef bad = table();
  bad.parts[2].shape = BoxDef{Vec3(0.05, -1, 0.35)};
  EXPECT_EQ(refusal(bad), "parts[2].shape.half_extents[1]: must be > 0");
  bad = table();
  bad.parts[1].shape = HalfSpaceDef{};
  EXPECT_NE(refusal(bad).find("parts[1].shape: a compound's parts must be convex"),
            std::string::npos);
  bad = table();
  bad.parts[3].shape = table();  // no compounds of compounds
  EXPECT_NE(refusal(bad).find("parts[3].shape: a compound's parts must be convex"),
            std::string::npos);
  bad = table();
  bad.parts[4].pose.orientation = Quat(0, 0, 0, 0);
  EXPECT_EQ(refusal(bad), "parts[4].pose.orientation: must be a finite, non-zero quaternion");
  bad = table();
  bad.parts[0].pose.position.y() = std::nan("");
  EXPECT_NE(refusal(bad).find("parts[0].pose.position: must be finite"), std::string::npos);
  bad.parts.assign(kMaxCompoundParts + 1, part(SphereDef{0.1}, Vec3::Zero()));
  EXPECT_EQ(refusal(bad), "parts: 257 parts, more than the 256 a compound may have");

  // A part thinner than the world's smallest size is named by its index.
  World world;
  BodyDef def;
  CompoundDef thin = table();
  thin.parts[3].shape = BoxDef{Vec3(0.05, 1e-7, 0.35)};
  def.shape = thin;
  def.mass = 1;
  const Result<BodyId> refused = world.create_body(def);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.status().message().find("shape.parts[3].half_extents"), std::string::npos)
      << refused.status().message();
  EXPECT_EQ(world.body_count(), 0u);
}

TEST(Compound, MassPropertiesAreTheParts) {
  // A dumbbell: two balls of radius r at +-d along x. Closed form: each ball's 2/5 m r^2 plus,
  // across the bar, m d^2.
  const double r = 0.2, d = 0.5, density = 1000;
  CompoundDef dumbbell;
  dumbbell.parts = {part(SphereDef{r}, Vec3(-d, 0, 0)), part(SphereDef{r}, Vec3(d, 0, 0))};
  const Shape shape = Shape::create(dumbbell).value();
  const double ball = density * 4.0 / 3.0 * std::numbers::pi * r * r * r;
  const MassProperties props = shape.mass_properties(density);
  EXPECT_NEAR(props.mass, 2 * ball, 1e-9 * ball);
  EXPECT_LT(props.center_of_mass.norm(), 1e-15);
  EXPECT_NEAR(props.inertia(0, 0), 2 * 0.4 * ball * r * r, 1e-12);
  EXPECT_NEAR(props.inertia(1, 1), 2 * (0.4 * ball * r * r + ball * d * d), 1e-12);
  EXPECT_NEAR(props.inertia(2, 2), props.inertia(1, 1), 1e-12);
  EXPECT_LT((props.inertia - props.inertia.transpose()).norm(), 1e-15);

  // One box part turned a quarter about z and moved: the box's own inertia with x and y swapped,
  // its centre of mass at the offset.
  const Vec3 half(0.3, 0.1, 0.2), offset(1, 2, 3);
  CompoundDef turned;
  turned.parts = {
      part(BoxDef{half}, offset, Quat(Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitZ())))};
  const MassProperties box = Shape::create(BoxDef{half}).value().mass_properties(density);
  const MassProperties one = Shape::create(turned).value().mass_properties(density);
  EXPECT_NEAR(one.mass, box.mass, 1e-12 * box.mass);
  EXPECT_LT((one.center_of_mass - offset).norm(), 1e-14);
  EXPECT_NEAR(one.inertia(0, 0), box.inertia(1, 1), 1e-12);
  EXPECT_NEAR(one.inertia(1, 1), box.inertia(0, 0), 1e-12);
  EXPECT_NEAR(one.inertia(2, 2), box.inertia(2, 2), 1e-12);

  // A body of a compound is centred at its centre of mass: the table's sits at the height of the
  // parts' mass-weighted centres, and its position reports it.
  World world;
  BodyDef def;
  def.shape = table();
  def.density = 500;
  def.position = Vec3(2, 0, 0);
  const BodyId id = world.create_body(def).value();
  const double top = 1.2 * 0.8 * 0.1, leg = 0.1 * 0.1 * 0.7;
  const double centre = (top * 0.75 + 4 * leg * 0.35) / (top + 4 * leg);
  EXPECT_NEAR(world.body(id)->position().z(), centre, 1e-12);
  EXPECT_NEAR(world.body(id)->mass(), 500 * (top + 4 * leg), 1e-9);
  const Aabb bounds = world.body(id)->shape().local_bounds();
  EXPECT_NEAR(bounds.min.z(), -centre, 1e-12);
  EXPECT_NEAR(bounds.max.z(), 0.8 - centre, 1e-12);
}

// The table dropped on `ground` stands on its four legs, level, at the height it stands at on
// the plane; each leg touches with its own manifold.
void expect_table_stands(const ShapeDef& ground, double floor_height) {
  World world;
  add_static(&world, ground);
  BodyDef def;
  def.shape = table();
  def.mass = 20;
  def.position = Vec3(0.1, -0.2, floor_height + 0.05);
  const BodyId id = world.create_body(def).value();
  run(&world, 240);
  const BodyView body = world.body(id);
  const double top = 1.2 * 0.8 * 0.1, leg = 0.1 * 0.1 * 0.7;
  const double centre = (top * 0.75 + 4 * leg * 0.35) / (top + 4 * leg);
  EXPECT_NEAR(body->position().z(), floor_height + centre, 0.01);
  EXPECT_LT(body->linear_velocity().norm(), 1e-3);
  EXPECT_LT(body->angular_velocity().norm(), 1e-3);
  EXPECT_GT((body->orientation() * Vec3::UnitZ()).z(), std::cos(0.001));
  const std::vector<Contact> contacts = every_contact(world);
  ASSERT_EQ(contacts.size(), 4u);  // one for each leg, none for the top
  for (const Contact& contact : contacts) {
    EXPECT_GE(contact.manifold.count, 3);  // a leg's foot is a face
    for (int i = 0; i < contact.manifold.count; ++i)
      EXPECT_LT(std::abs(contact.manifold.points[i].point_b.z() - floor_height), 0.01);
  }
}

TEST(Compound, ATableStandsOnItsLegsOnThePlane) {
  expect_table_stands(HalfSpaceDef{}, 0);
}

TEST(Compound, ATableStandsOnAHeightfieldAndOnAMesh) {
  const HeightFieldDef floor = field_of(9, 9, 0.5, [](double, double) { return 0.25; });
  expect_table_stands(floor, 0.25);
  expect_table_stands(mesh_of_height_field(HeightField::create(floor).value()), 0.25);
}

TEST(Compound, TwoCompoundsMeetPartToPart) {
  // A table stacked on a table: the upper one's four legs stand on the lower one's top, and
  // nothing sinks; the lower one's legs hold both.
  World world;
  add_static(&world, HalfSpaceDef{});
  BodyDef def;
  def.shape = table();
  def.mass = 20;
  const BodyId lower = world.create_body(def).value();
  def.position = Vec3(0, 0, 0.82);
  const BodyId upper = world.create_body(def).value();
  run(&world, 300);
  EXPECT_NEAR(world.body(upper)->position().z() - world.body(lower)->position().z(), 0.8, 0.01);
  EXPECT_LT(world.body(upper)->linear_velocity().norm(), 1e-3);
  std::size_t between = 0;
  const std::vector<Contact> contacts = every_contact(world);
  for (const Contact& contact : contacts)
    if (contact.a.index != 0 && contact.b.index != 0) ++between;
  EXPECT_EQ(between, 4u);
  EXPECT_EQ(contacts.size(), 8u);
}

TEST(Compound, ADumbbellRollsOnItsBalls) {
  // Two balls of radius 0.2 on a thin bar: it rolls along the ground on the balls; the bar,
  // 0.15 m above the ground, never touches. Rolling without slipping at v, each ball turns at
  // v / r.
  World world;
  add_static(&world, HalfSpaceDef{});
  CompoundDef dumbbell;
  dumbbell.parts = {part(SphereDef{0.2}, Vec3(0, -0.5, 0)), part(SphereDef{0.2}, Vec3(0, 0.5, 0)),
                    part(CapsuleDef{0.05, 0.4}, Vec3::Zero(),
                         Quat(Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitX())))};
  BodyDef def;
  def.shape = dumbbell;
  def.density = 1000;
  def.position = Vec3(0, 0, 0.2);
  def.linear_velocity = Vec3(1, 0, 0);
  const BodyId id = world.create_body(def).value();
  run(&world, 120);
  const BodyView body = world.body(id);
  EXPECT_NEAR(body->position().z(), 0.2, 0.005);
  const double v = body->linear_velocity().x();
  EXPECT_GT(v, 0.3);
  EXPECT_NEAR(body->angular_velocity().y(), v / 0.2, 0.02 * v / 0.2);
  EXPECT_EQ(every_contact(world).size(), 2u);
}

TEST(Compound, RaysAndOverlapsSeeThePartsNotTheGaps) {
  World world;
  BodyDef def;
  def.shape = table();
  def.type = BodyType::kStatic;
  const BodyId id = world.create_body(def).value();
  // Down through the top.
  RayCast down;
  down.origin = Vec3(0.1, 0.1, 2);
  down.direction = -Vec3::UnitZ();
  Result<RayHit> hit = world.cast_ray(down);
  ASSERT_TRUE(hit && hit.value().hit());
  EXPECT_EQ(hit.value().body, id);
  EXPECT_NEAR(hit.value().distance, 2 - 0.8, 1e-12);
  EXPECT_LT((hit.value().normal - Vec3::UnitZ()).norm(), 1e-12);
  // Along the floor under the top, between the legs: nothing; at a leg's height past it: the leg.
  RayCast across;
  across.origin = Vec3(-2, 0, 0.3);
  across.direction = Vec3::UnitX();
  hit = world.cast_ray(across);
  ASSERT_TRUE(hit);
  EXPECT_FALSE(hit.value().hit());
  across.origin.y() = 0.35;
  hit = world.cast_ray(across);
  ASSERT_TRUE(hit && hit.value().hit());
  EXPECT_NEAR(hit.value().point.x(), -0.6, 1e-12);
  EXPECT_LT((hit.value().normal + Vec3::UnitX()).norm(), 1e-12);

  // A ball under the top, between the legs, overlaps nothing; grown to the top's underside, it
  // does.
  OverlapQuery query;
  query.shape = SphereDef{0.2};
  query.pose.position = Vec3(0, 0, 0.4);
  std::vector<BodyId> found;
  ASSERT_TRUE(world.overlap(query, 8, &found));
  EXPECT_TRUE(found.empty());
  query.shape = SphereDef{0.31};
  ASSERT_TRUE(world.overlap(query, 8, &found));
  EXPECT_EQ(found, std::vector<BodyId>{id});

  // A compound is a query's shape too: two balls 1 m apart straddle a leg without touching it.
  CompoundDef pair;
  pair.parts = {part(SphereDef{0.1}, Vec3(0, -0.2, 0)), part(SphereDef{0.1}, Vec3(0, 0.2, 0))};
  query.shape = pair;
  query.pose.position = Vec3(0.55, 0.35, 0.3);
  ASSERT_TRUE(world.overlap(query, 8, &found));
  EXPECT_TRUE(found.empty());
  query.pose.position.y() = 0.2;
  ASSERT_TRUE(world.overlap(query, 8, &found));
  EXPECT_EQ(found, std::vector<BodyId>{id});
}

TEST(Compound, APairKeepsItsDeepestManifoldsAndSaysSo) {
  // 100 balls in a grid, one body, resting on the ground: 100 touching parts, more than a pair
  // keeps. The deepest kept, the flag raised, and the body still held up.
  CompoundDef raft;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j)
      raft.parts.push_back(part(SphereDef{0.1}, Vec3(0.2 * i, 0.2 * j, 0)));
  const Shape shape = Shape::create(raft).value();
  const Shape ground = Shape::create(HalfSpaceDef{}).value();
  CollisionSettings settings;
  ContactManifold deepest;
  const Pose tilted{Vec3(0, 0, 0.09), Quat(Eigen::AngleAxisd(-0.01, Vec3::UnitX()))};
  const std::uint32_t flags = collide(shape, tilted, ground, Pose{}, settings, &deepest);
  EXPECT_NE(flags & kPairManifoldLimit, 0u);
  EXPECT_NEAR(deepest.depth, 0.01 + std::sin(0.01) * 1.8, 1e-6);
  // Two rafts heaped into one another: 10,000 pairs of parts within reach, of which a pair of
  // bodies meets at most kMaxPartPairs; still an answer, and the flag.
  const std::uint32_t heaped = collide(
      shape, Pose{}, shape, Pose{Vec3(0.01, 0.01, 0), Quat::Identity()}, settings, &deepest);
  EXPECT_NE(heaped & kPairManifoldLimit, 0u);
  EXPECT_GT(deepest.count, 0);

  World world;
  add_static(&world, HalfSpaceDef{});
  BodyDef def;
  def.shape = raft;
  def.mass = 10;
  def.position = Vec3(0, 0, 0.1);
  const BodyId id = world.create_body(def).value();
  run(&world, 30);
  EXPECT_NE(world.last_step().collision_flags & kPairManifoldLimit, 0u);
  EXPECT_EQ(every_contact(world).size(), kMaxPairManifolds);
  EXPECT_NEAR(world.body(id)->position().z(), 0.1, 0.005);
}

TEST(Compound, SnapshotsAreBitForBit) {
  World world;
  add_static(&world, HalfSpaceDef{});
  BodyDef def;
  def.shape = table();
  def.mass = 20;
  def.position = Vec3(0, 0, 0.3);
  def.orientation = Quat(Eigen::AngleAxisd(0.3, Vec3(1, 1, 0).normalized()));
  world.create_body(def).value();
  def.position = Vec3(0.2, 0.1, 1.6);
  world.create_body(def).value();
  run(&world, 30);
  const std::string bytes = world.save_state();
  Result<World> copy = World::from_state(world.settings(), bytes);
  ASSERT_TRUE(copy) << copy.status().message();
  EXPECT_EQ(copy.value().save_state(), bytes);
  run(&world, 60);
  run(&copy.value(), 60);
  EXPECT_EQ(copy.value().save_state(), world.save_state());
  // Cut anywhere, the bytes are refused with a message, never read past.
  for (std::size_t cut = bytes.size() / 2; cut < bytes.size(); cut += 97)
    EXPECT_FALSE(World::from_state(world.settings(), bytes.substr(0, cut)));
}

}  // namespace
}  // namespace tumble
