#include "scenes/standard.h"

#include <charconv>
#include <cmath>
#include <numbers>
#include <string>

namespace tumble {
namespace {

BodyDef ground() {
  BodyDef def;
  def.shape = HalfSpaceDef{};
  def.type = BodyType::kStatic;
  def.friction = 0.5;
  return def;
}

BodyDef box(const Vec3& size, double mass, const Vec3& position) {
  BodyDef def;
  def.shape = BoxDef{0.5 * size};
  def.mass = mass;
  def.position = position;
  def.friction = 0.5;
  return def;
}

SceneDef base_scene(std::string name, double duration) {
  SceneDef scene;
  scene.name = std::move(name);
  scene.duration = duration;
  scene.dt = 1.0 / 60;
  return scene;
}

}  // namespace

SceneDef pile_scene(int count) {
  SceneDef scene = base_scene("pile-" + std::to_string(count), 10);
  scene.bodies.push_back(ground());
  const int side = static_cast<int>(std::ceil(std::cbrt(static_cast<double>(count)) - 1e-9));
  SceneRandom random;
  for (int i = 0; i < count; ++i) {
    const int ix = i % side, iy = (i / side) % side, iz = i / (side * side);
    const Vec3 centre((ix - (side - 1) / 2.0) * 1.5, (iy - (side - 1) / 2.0) * 1.5, 2.0 + 1.5 * iz);
    Vec3 r;
    for (int k = 0; k < 3; ++k)
      r[k] = 0.2 * (2 * random.uniform() - 1);
    BodyDef def = box(Vec3::Ones(), 1, centre);
    const double angle = r.norm();
    if (angle > 0) def.orientation = Quat(Eigen::AngleAxisd(angle, r / angle));
    scene.bodies.push_back(def);
  }
  return scene;
}

SceneDef terrain_pile_scene(int count) {
  SceneDef scene = pile_scene(count);
  scene.name = "terrain-" + std::to_string(count);
  // Rolling hills under the pile, 0.5 m cells, up to about 0.55 m high: below the lowest box
  // (its centre 2 m up), and wide enough (60 m for 1000 boxes) that no box slides off. Taller
  // piles throw their boxes farther as their towers topple (from 2197 boxes, one at 17 m/s):
  // past 1000, the hills grow twice as fast as the pile's side.
  const int side = static_cast<int>(std::ceil(std::cbrt(static_cast<double>(count)) - 1e-9));
  const double half_width = std::max(1.5 * side + 15, 5.0 * side - 20);
  HeightFieldDef terrain;
  terrain.spacing_x = terrain.spacing_y = 0.5;
  terrain.samples_x = terrain.samples_y = static_cast<std::uint32_t>(2 * half_width / 0.5) + 1;
  for (std::uint32_t j = 0; j < terrain.samples_y; ++j)
    for (std::uint32_t i = 0; i < terrain.samples_x; ++i) {
      const double x = (i - 0.5 * (terrain.samples_x - 1)) * 0.5;
      const double y = (j - 0.5 * (terrain.samples_y - 1)) * 0.5;
      terrain.heights.push_back(0.4 * std::sin(0.35 * x) * std::cos(0.3 * y) +
                                0.15 * std::sin(0.9 * x + 0.7 * y));
    }
  scene.bodies.front().shape = std::move(terrain);
  return scene;
}

SceneDef terrain_mesh_pile_scene(int count) {
  SceneDef scene = terrain_pile_scene(count);
  scene.name = "terrain-mesh-" + std::to_string(count);
  BodyDef& ground = scene.bodies.front();
  ground.shape =
      mesh_of_height_field(HeightField::create(std::get<HeightFieldDef>(ground.shape)).value());
  return scene;
}

// Bodies of parts, each within the pile's 1 m box: a jack (three 1 x 0.2 x 0.2 m bars crossing at
// its centre) and a dumbbell (two balls of 0.25 m on a bar), in turn.
CompoundDef jack() {
  CompoundDef def;
  for (int axis = 0; axis < 3; ++axis) {
    Vec3 size = Vec3::Constant(0.2);
    size[axis] = 1.0;
    def.parts.push_back({BoxDef::of_size(size), Pose{}});
  }
  return def;
}

CompoundDef dumbbell() {
  CompoundDef def;
  def.parts = {{SphereDef{0.25}, Pose{Vec3(-0.25, 0, 0), Quat::Identity()}},
               {SphereDef{0.25}, Pose{Vec3(0.25, 0, 0), Quat::Identity()}},
               {CapsuleDef{0.08, 0.2},
                Pose{Vec3::Zero(), Quat(0.5 * std::sqrt(2.0), 0, 0.5 * std::sqrt(2.0), 0)}}};
  return def;
}

SceneDef compound_pile_scene(int count) {
  SceneDef scene = pile_scene(count);
  scene.name = "compound-pile-" + std::to_string(count);
  for (std::size_t i = 1; i < scene.bodies.size(); ++i) {
    BodyDef& body = scene.bodies[i];
    body.shape = i % 2 == 1 ? ShapeDef{jack()} : ShapeDef{dumbbell()};
    body.mass = 1;
  }
  return scene;
}

SceneDef pyramid_scene(int base) {
  SceneDef scene = base_scene("pyramid-" + std::to_string(base), 20);
  scene.bodies.push_back(ground());
  for (int k = 0; k < base; ++k)
    for (int j = 0; j < base - k; ++j)
      scene.bodies.push_back(
          box(Vec3::Ones(), 1, Vec3((j - (base - k - 1) / 2.0) * 1.01, 0, 0.5 + k)));
  return scene;
}

SceneDef tower_scene(int height) {
  SceneDef scene = base_scene("tower-" + std::to_string(height), 20);
  scene.bodies.push_back(ground());
  for (int k = 0; k < height; ++k)
    scene.bodies.push_back(box(Vec3::Ones(), 1, Vec3(0, 0, 0.5 + k)));
  return scene;
}

SceneDef mass_ratio_scene(bool inverted) {
  SceneDef scene = base_scene(inverted ? "mass-ratio-inv" : "mass-ratio", 10);
  scene.bodies.push_back(ground());
  const double masses[3] = {inverted ? 1000.0 : 1.0, 1.0, inverted ? 1.0 : 1000.0};
  for (int k = 0; k < 3; ++k)
    scene.bodies.push_back(box(Vec3::Ones(), masses[k], Vec3(0, 0, 0.5 + k)));
  return scene;
}

SceneDef bullet_scene() {
  SceneDef scene = base_scene("bullet", 1);
  scene.world.gravity = Vec3::Zero();
  BodyDef projectile = box(Vec3::Constant(0.1), 1, Vec3(-6, 0, 0));
  projectile.linear_velocity = Vec3(300, 0, 0);
  BodyDef wall = box(Vec3(0.05, 10, 10), 0, Vec3::Zero());
  wall.type = BodyType::kStatic;
  scene.bodies = {projectile, wall};
  return scene;
}

SceneDef slide_scene(double speed) {
  SceneDef scene = base_scene("slide", 3);
  BodyDef slider = box(Vec3::Ones(), 1, Vec3(0, 0, 0.5));
  slider.linear_velocity = Vec3(speed, 0, 0);
  scene.bodies = {ground(), slider};
  return scene;
}

SceneDef spin_scene() {
  SceneDef scene = base_scene("spin", 20);
  scene.world.gravity = Vec3::Zero();
  BodyDef spinner = box(Vec3(1, 2, 3), 1, Vec3::Zero());
  spinner.angular_velocity = Vec3(0.01, 5, 0.01);
  scene.bodies = {spinner};
  return scene;
}

SceneDef carousel_scene(double turn) {
  SceneDef scene = base_scene("carousel", 20);
  scene.bodies.push_back(ground());
  BodyDef deck = box(Vec3(8, 8, 0.2), 0, Vec3(0, 0, 0.3));
  deck.type = BodyType::kKinematic;
  deck.angular_velocity = Vec3(0, 0, turn);
  scene.bodies.push_back(deck);
  const double radius = 2.5, size = 0.5;
  for (int side = 0; side < 4; ++side) {
    const double angle = side * std::numbers::pi / 2;
    const Vec3 at(radius * std::cos(angle), radius * std::sin(angle), 0);
    for (int level = 0; level < 5; ++level) {
      BodyDef b = box(Vec3::Constant(size), 1, at + Vec3(0, 0, 0.4 + size * (level + 0.5)));
      b.friction = 0.8;
      b.linear_velocity = deck.angular_velocity.cross(at);  // where it stands, the deck's
      b.angular_velocity = deck.angular_velocity;
      scene.bodies.push_back(b);
    }
  }
  return scene;
}

SceneDef bounce_scene(double height, double restitution) {
  SceneDef scene = base_scene("bounce", 3);
  BodyDef dropped = box(Vec3::Ones(), 1, Vec3(0, 0, 0.5 + height));
  dropped.restitution = restitution;
  BodyDef floor = ground();
  floor.restitution = restitution;
  scene.bodies = {floor, dropped};
  return scene;
}

namespace {

// A name as errors show it: a request may carry megabytes of it.
std::string shown(std::string_view spec) {
  constexpr std::size_t kShown = 64;
  return spec.size() <= kShown ? std::string(spec)
                               : std::string(spec.substr(0, kShown)) + "... (" +
                                     std::to_string(spec.size()) + " characters)";
}

Result<SceneDef> build_standard_scene(std::string_view spec, std::size_t max_bodies);

}  // namespace

Result<SceneDef> standard_scene(std::string_view spec, std::size_t max_bodies) {
  Result<SceneDef> made = build_standard_scene(spec, max_bodies);
  // The scenes without a size are small, but a server may allow fewer bodies still.
  if (made && made.value().bodies.size() > max_bodies)
    return Status::error("scene '" + shown(spec) +
                         "': " + std::to_string(made.value().bodies.size()) +
                         " bodies, more than the " + std::to_string(max_bodies) + " allowed");
  return made;
}

SceneDef pendulum_scene() {
  SceneDef scene = base_scene("pendulum", 10);
  scene.bodies.push_back(ground());
  BodyDef bob;
  bob.shape = SphereDef{0.05};
  bob.mass = 1;
  bob.position = Vec3(1, 0, 2);
  scene.bodies.push_back(bob);
  SceneJoint rod;
  rod.def.kind = JointKind::kDistance;
  rod.def.anchor = bob.position;
  rod.def.anchor_b = Vec3(0, 0, 2);
  rod.a = 1;
  scene.joints.push_back(rod);
  return scene;
}

SceneDef chain_scene(int links, double end_ratio) {
  SceneDef scene = base_scene("chain-" + std::to_string(links), 10);
  if (end_ratio != 1) scene.name += "-" + std::to_string(std::lround(end_ratio));
  scene.bodies.push_back(ground());
  const Vec3 top(0, 0, 0.2 * links + 1);
  for (int i = 0; i < links; ++i) {
    scene.bodies.push_back(box(Vec3(0.2, 0.04, 0.04), i == links - 1 ? 0.5 * end_ratio : 0.5,
                               top + Vec3(0.2 * i + 0.1, 0, 0)));
    SceneJoint joint;
    joint.def.kind = JointKind::kBall;
    joint.def.anchor = top + Vec3(0.2 * i, 0, 0);
    joint.a = scene.bodies.size() - 1;
    if (i > 0) joint.b = scene.bodies.size() - 2;
    scene.joints.push_back(joint);
  }
  return scene;
}

SceneDef hanging_chain_scene(int links, double end_ratio) {
  SceneDef scene = base_scene("hanging-chain-" + std::to_string(links), 20);
  scene.world.solver.sleeping = false;
  const Vec3 pivot(0, 0, 0.2 * links + 1);
  for (int i = 0; i < links; ++i) {
    BodyDef link = box(Vec3(0.04, 0.04, 0.2), i == links - 1 ? 0.5 * end_ratio : 0.5,
                       pivot - Vec3(0, 0, 0.2 * (i + 0.5)));
    if (i == links - 1) link.linear_velocity = Vec3(1, 0, 0);
    scene.bodies.push_back(link);
    SceneJoint joint;
    joint.def.kind = JointKind::kBall;
    joint.def.anchor = pivot - Vec3(0, 0, 0.2 * i);
    joint.a = scene.bodies.size() - 1;
    if (i > 0) joint.b = scene.bodies.size() - 2;
    scene.joints.push_back(joint);
  }
  return scene;
}

SceneDef double_pendulum_scene() {
  SceneDef scene = base_scene("double-pendulum", 20);
  scene.bodies.push_back(ground());
  for (int i = 0; i < 2; ++i) {
    BodyDef bob;
    bob.shape = SphereDef{0.05};
    bob.mass = 1;
    bob.position = Vec3(i + 1.0, 0, 3);
    scene.bodies.push_back(bob);
    SceneJoint rod;
    rod.def.kind = JointKind::kDistance;
    rod.def.anchor = bob.position;
    rod.def.anchor_b = Vec3(i, 0, 3);
    rod.a = scene.bodies.size() - 1;
    if (i > 0) rod.b = scene.bodies.size() - 2;
    scene.joints.push_back(rod);
  }
  return scene;
}

SceneDef cradle_scene() {
  SceneDef scene = base_scene("cradle", 10);
  scene.bodies.push_back(ground());
  const double radius = 0.05, length = 1, top = 1.5;
  for (int i = 0; i < 5; ++i) {
    const Vec3 pivot(2 * radius * i, 0, top);
    BodyDef ball;
    ball.shape = SphereDef{radius};
    ball.mass = 1;
    ball.restitution = 1;
    ball.friction = 0;
    // The first ball is pulled out 45 degrees; the others hang touching.
    const double angle = i == 0 ? -std::numbers::pi / 4 : 0;
    ball.position = pivot + length * Vec3(std::sin(angle), 0, -std::cos(angle));
    scene.bodies.push_back(ball);
    SceneJoint rod;
    rod.def.kind = JointKind::kDistance;
    rod.def.anchor = ball.position;
    rod.def.anchor_b = pivot;
    rod.a = scene.bodies.size() - 1;
    scene.joints.push_back(rod);
  }
  return scene;
}

SceneDef hinged_cradle_scene(int balls) {
  SceneDef scene = base_scene("hinged-cradle", 1.5);
  scene.world.solver.sleeping = false;
  const double radius = 0.05, top = 1.5;
  for (int i = 0; i < balls; ++i) {
    const Vec3 pivot(2 * radius * i, 0, top);
    const double angle = i == 0 ? -std::numbers::pi / 4 : 0;
    BodyDef ball;
    ball.shape = SphereDef{radius};
    ball.mass = 1;
    ball.restitution = 1;
    ball.friction = 0;
    ball.position = pivot + Vec3(std::sin(angle), 0, -std::cos(angle));
    scene.bodies.push_back(ball);
    SceneJoint hinge;
    hinge.def.kind = JointKind::kHinge;
    hinge.def.anchor = pivot;
    hinge.def.axis = Vec3::UnitY();
    hinge.a = scene.bodies.size() - 1;
    scene.joints.push_back(hinge);
  }
  return scene;
}

SceneDef door_scene() {
  SceneDef scene = base_scene("door", 10);
  scene.bodies.push_back(ground());
  // A 1 m x 2 m door of 20 kg hinged along its edge at x = 0, pushed open at 4 rad/s about the
  // hinge: it swings to its stop at a quarter turn and its spring closes it again.
  BodyDef door = box(Vec3(1, 0.05, 2), 20, Vec3(0.5, 0, 1.01));
  door.angular_velocity = Vec3(0, 0, 4);
  door.linear_velocity = Vec3(0, 2, 0);  // the centre, 0.5 m from the hinge
  scene.bodies.push_back(door);
  SceneJoint hinge;
  hinge.def.kind = JointKind::kHinge;
  hinge.def.anchor = Vec3(0, 0, 1.01);
  hinge.def.axis = Vec3::UnitZ();
  hinge.def.limit = {true, -std::numbers::pi / 2, 0};  // b (the world) turns back as the door opens
  hinge.def.spring = {true, 0, 20, 4};
  hinge.a = 1;
  scene.joints.push_back(hinge);
  return scene;
}

SceneDef rope_bridge_scene(int planks) {
  SceneDef scene = base_scene("rope-bridge-" + std::to_string(planks), 10);
  scene.bodies.push_back(ground());
  // Planks 0.3 m long across a gap, hinged to each other about y and to the world at both ends:
  // the joints close a loop through the world (solved by Gauss-Seidel sweeps).
  const double plank = 0.3, height = 3;
  for (int i = 0; i < planks; ++i) {
    scene.bodies.push_back(box(Vec3(plank - 0.02, 1, 0.05), 2, Vec3(plank * (i + 0.5), 0, height)));
    SceneJoint joint;
    joint.def.kind = JointKind::kHinge;
    joint.def.axis = Vec3::UnitY();
    joint.def.anchor = Vec3(plank * i, 0, height);
    joint.a = scene.bodies.size() - 1;
    if (i > 0) joint.b = scene.bodies.size() - 2;
    scene.joints.push_back(joint);
  }
  SceneJoint end;
  end.def.kind = JointKind::kHinge;
  end.def.axis = Vec3::UnitY();
  end.def.anchor = Vec3(plank * planks, 0, height);
  end.a = scene.bodies.size() - 1;
  scene.joints.push_back(end);
  return scene;
}

SceneDef arm_scene() {
  SceneDef scene = base_scene("arm", 10);
  scene.bodies.push_back(ground());
  const double height = 0.5;
  // Links from the base out: size, mass, centre; each joint's anchor and axis, to the link before
  // (the world for the base).
  struct Link {
    Vec3 size;
    double mass;
    Vec3 centre, anchor, axis;
  };
  const Link links[] = {
      {{0.2, 0.2, 0.4}, 4, {0, 0, 0.3}, {0, 0, 0.1}, Vec3::UnitZ()},                  // base yaw
      {{0.6, 0.1, 0.1}, 3, {0.3, 0, height}, {0, 0, height}, Vec3::UnitY()},          // shoulder
      {{0.5, 0.08, 0.08}, 2, {0.85, 0, height}, {0.6, 0, height}, Vec3::UnitY()},     // elbow
      {{0.1, 0.08, 0.08}, 0.5, {1.15, 0, height}, {1.1, 0, height}, Vec3::UnitX()},   // roll
      {{0.1, 0.08, 0.08}, 0.5, {1.25, 0, height}, {1.2, 0, height}, Vec3::UnitY()},   // pitch
      {{0.1, 0.08, 0.08}, 0.3, {1.35, 0, height}, {1.3, 0, height}, Vec3::UnitX()}};  // roll
  for (std::size_t i = 0; i < std::size(links); ++i) {
    scene.bodies.push_back(box(links[i].size, links[i].mass, links[i].centre));
    SceneJoint joint;
    joint.def.kind = JointKind::kHinge;
    joint.def.anchor = links[i].anchor;
    joint.def.axis = links[i].axis;
    joint.def.motor = {true, i == 0 ? 0.5 : 0.0, 300};  // N m: the shoulder carries ~85
    joint.a = scene.bodies.size() - 1;
    if (i > 0) joint.b = scene.bodies.size() - 2;
    scene.joints.push_back(joint);
  }
  scene.bodies.push_back(box(Vec3(0.2, 0.2, 0.2), 5, Vec3(1.5, 0, height)));  // the payload
  SceneJoint grip;
  grip.def.kind = JointKind::kFixed;
  grip.def.anchor = Vec3(1.4, 0, height);
  grip.a = scene.bodies.size() - 1;
  grip.b = scene.bodies.size() - 2;
  scene.joints.push_back(grip);
  return scene;
}

namespace {

// Every ragdoll joint's friction (N m): under the lightest limb's weight about its joint (a
// forearm's, 2.2 N m), so limbs still fall, and enough that a ragdoll at rest comes to a stop and
// sleeps (without it a head kept rolling on the ground in its neck's cone for minutes).
constexpr double kRagdollJointFriction = 1.0;

// One ragdoll standing with its feet at `at`, facing +y turned by `yaw` about z.
void add_ragdoll(SceneDef& scene, const Vec3& at, double yaw) {
  const Quat turn(Eigen::AngleAxisd(yaw, Vec3::UnitZ()));
  auto place = [&](const Vec3& local) { return Vec3(at + turn * local); };
  auto limb = [&](double radius, double length, double mass, const Vec3& centre) {
    BodyDef def;
    def.shape = CapsuleDef{radius, length / 2 - radius};
    def.mass = mass;
    def.position = place(centre);
    def.orientation = turn;
    def.friction = 0.5;
    return def;
  };
  auto part = [&](BodyDef def) {
    def.orientation = turn;
    def.position = place(def.position);
    scene.bodies.push_back(def);
    return scene.bodies.size() - 1;
  };
  auto join = [&](JointKind kind, std::size_t a, std::size_t b, const Vec3& anchor,
                  const Vec3& axis, double swing, JointLimit limit) {
    SceneJoint joint;
    joint.def.kind = kind;
    joint.def.anchor = place(anchor);
    joint.def.axis = turn * axis;
    if (kind == JointKind::kBall) joint.def.max_swing = swing;
    joint.def.limit = limit;
    joint.def.friction = kRagdollJointFriction;
    joint.a = a;
    joint.b = b;
    scene.joints.push_back(joint);
  };
  const std::size_t pelvis = part(box(Vec3(0.3, 0.2, 0.15), 8, Vec3(0, 0, 1.0)));
  const std::size_t torso = part(box(Vec3(0.35, 0.2, 0.4), 15, Vec3(0, 0, 1.3)));
  BodyDef head_def;
  head_def.shape = SphereDef{0.1};
  head_def.mass = 4;
  head_def.position = Vec3(0, 0, 1.65);
  head_def.friction = 0.5;
  const std::size_t head = part(head_def);
  const JointLimit none;
  join(JointKind::kBall, torso, pelvis, {0, 0, 1.1}, Vec3::UnitZ(), 0.5, {true, -0.4, 0.4});
  join(JointKind::kBall, head, torso, {0, 0, 1.53}, Vec3::UnitZ(), 0.6, {true, -0.8, 0.8});
  for (double side : {-1.0, 1.0}) {
    scene.bodies.push_back(limb(0.05, 0.3, 2, Vec3(0.25 * side, 0, 1.33)));
    const std::size_t upper_arm = scene.bodies.size() - 1;
    scene.bodies.push_back(limb(0.045, 0.3, 1.5, Vec3(0.25 * side, 0, 1.03)));
    const std::size_t forearm = scene.bodies.size() - 1;
    join(JointKind::kBall, upper_arm, torso, {0.25 * side, 0, 1.48}, Vec3::UnitZ(), 1.5, none);
    join(JointKind::kHinge, forearm, upper_arm, {0.25 * side, 0, 1.18}, Vec3::UnitX(), 0,
         {true, -2.5, 0});
    scene.bodies.push_back(limb(0.06, 0.4, 7, Vec3(0.1 * side, 0, 0.7)));
    const std::size_t thigh = scene.bodies.size() - 1;
    scene.bodies.push_back(limb(0.05, 0.4, 4, Vec3(0.1 * side, 0, 0.28)));
    const std::size_t shin = scene.bodies.size() - 1;
    join(JointKind::kBall, thigh, pelvis, {0.1 * side, 0, 0.9}, Vec3::UnitZ(), 1.2, none);
    join(JointKind::kHinge, shin, thigh, {0.1 * side, 0, 0.49}, Vec3::UnitX(), 0, {true, 0, 2.5});
  }
}

}  // namespace

SceneDef ragdolls_scene(int ragdolls) {
  SceneDef scene = base_scene("ragdolls-" + std::to_string(ragdolls), 10);
  scene.bodies.push_back(ground());
  // Four a layer on a 1 m square, each layer 2 m above the one below and turned a quarter turn.
  for (int i = 0; i < ragdolls; ++i) {
    const int layer = i / 4, slot = i % 4;
    const Vec3 at((slot % 2) - 0.5, (slot / 2) - 0.5, 0.05 + 2.0 * layer);
    add_ragdoll(scene, at, std::numbers::pi / 2 * layer + 0.3 * slot);
  }
  return scene;
}

namespace {

Result<SceneDef> build_standard_scene(std::string_view spec, std::size_t max_bodies) {
  std::string_view name = spec;
  std::optional<int> size;
  std::optional<int> ratio;  // chain:N:R alone
  if (const std::size_t colon = spec.find(':'); colon != std::string_view::npos) {
    name = spec.substr(0, colon);
    std::string_view digits = spec.substr(colon + 1);
    if (const std::size_t second = digits.find(':');
        name == "chain" && second != std::string_view::npos) {
      const std::string_view ratio_digits = digits.substr(second + 1);
      digits = digits.substr(0, second);
      int value = 0;
      const auto [end, error] =
          std::from_chars(ratio_digits.data(), ratio_digits.data() + ratio_digits.size(), value);
      if (error != std::errc() || end != ratio_digits.data() + ratio_digits.size() || value < 1 ||
          value > 1000000)
        return Status::error("scene '" + shown(spec) +
                             "': the end's mass ratio after the second ':' must be an integer in "
                             "[1, 1000000]");
      ratio = value;
    }
    int value = 0;
    const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (error != std::errc() || end != digits.data() + digits.size() || value < 1 ||
        value > 1000000)
      return Status::error("scene '" + shown(spec) +
                           "': the size after ':' must be an integer in [1, 1000000]");
    size = value;
  }
  // Counted, ground included, before anything is built, so a request for a huge scene costs
  // nothing.
  if (name == "pile" || name == "terrain" || name == "terrain-mesh" || name == "compound-pile" ||
      name == "pyramid" || name == "tower" || name == "chain" || name == "rope-bridge" ||
      name == "ragdolls") {
    const bool piled =
        name == "pile" || name == "terrain" || name == "terrain-mesh" || name == "compound-pile";
    const std::uint64_t n = static_cast<std::uint64_t>(size.value_or(piled ? 1000 : 20));
    const std::uint64_t bodies = (name == "pyramid"    ? n * (n + 1) / 2
                                  : name == "ragdolls" ? 11 * n
                                                       : n) +
                                 1;
    if (bodies > max_bodies)
      return Status::error("scene '" + shown(spec) + "': " + std::to_string(bodies) +
                           " bodies with the ground, more than the " + std::to_string(max_bodies) +
                           " allowed");
  }
  auto sized = [&](const char* what) -> Status {
    if (size) return Status::error("scene '" + shown(spec) + "': " + what + " takes no size");
    return Status::ok();
  };
  if (name == "pile") return pile_scene(size.value_or(1000));
  if (name == "terrain") return terrain_pile_scene(size.value_or(1000));
  if (name == "terrain-mesh") return terrain_mesh_pile_scene(size.value_or(1000));
  if (name == "compound-pile") return compound_pile_scene(size.value_or(1000));
  if (name == "pyramid") return pyramid_scene(size.value_or(20));
  if (name == "tower") return tower_scene(size.value_or(20));
  if (name == "mass-ratio" || name == "mass-ratio-inv") {
    if (Status s = sized("mass-ratio"); !s) return s;
    return mass_ratio_scene(name == "mass-ratio-inv");
  }
  if (name == "bullet") {
    if (Status s = sized("bullet"); !s) return s;
    return bullet_scene();
  }
  if (name == "slide") {
    if (Status s = sized("slide"); !s) return s;
    return slide_scene();
  }
  if (name == "spin") {
    if (Status s = sized("spin"); !s) return s;
    return spin_scene();
  }
  if (name == "bounce") {
    if (Status s = sized("bounce"); !s) return s;
    return bounce_scene();
  }
  if (name == "carousel") {
    if (Status s = sized("carousel"); !s) return s;
    return carousel_scene();
  }
  if (name == "chain") return chain_scene(size.value_or(20), ratio.value_or(1));
  if (name == "rope-bridge") return rope_bridge_scene(size.value_or(20));
  if (name == "double-pendulum") {
    if (Status s = sized("double-pendulum"); !s) return s;
    return double_pendulum_scene();
  }
  if (name == "cradle") {
    if (Status s = sized("cradle"); !s) return s;
    return cradle_scene();
  }
  if (name == "door") {
    if (Status s = sized("door"); !s) return s;
    return door_scene();
  }
  if (name == "pendulum") {
    if (Status s = sized("pendulum"); !s) return s;
    return pendulum_scene();
  }
  if (name == "arm") {
    if (Status s = sized("arm"); !s) return s;
    return arm_scene();
  }
  if (name == "ragdolls") return ragdolls_scene(size.value_or(20));
  if (name == "default") {
    if (Status s = sized("default"); !s) return s;
    return parse_scene(default_scene_json());
  }
  return Status::error(
      "scene '" + shown(spec) +
      "': unknown; the standard scenes are pile, terrain, terrain-mesh, compound-pile, pyramid, "
      "tower, "
      "mass-ratio, mass-ratio-inv, bullet, slide, spin, bounce, pendulum, double-pendulum, "
      "chain, cradle, door, rope-bridge, arm, ragdolls, carousel, default");
}

}  // namespace

Result<SceneDef> chosen_scene(const std::string& file, const std::string& standard) {
  if (!file.empty()) return load_scene_file(file);
  if (!standard.empty()) return standard_scene(standard);
  return parse_scene(default_scene_json());
}

}  // namespace tumble
