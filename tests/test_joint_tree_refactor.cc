// A stiffened velocity factoring that starts from the last position pass's factors forms and
// eliminates again only the joints the stiffness changes (JointTree::refactor_stiffened): it
// must give the bits of forming and eliminating every joint of the same rows. Run whole and
// partial here, on chains (every joint three rows wide, each hub a link's two joints) and on a
// branching mobile (a hub of four joints, hinges and a fixed joint: widths three, five and six),
// the states must agree bit for bit, and the partial path must have run. (The chains alone would
// not notice a changed joint's hub left unmarked: each link's two joints hold the same body, stiff
// or not. The mobile does: 102 partial factorings in, its state differed.)
#include <gtest/gtest.h>

#include <optional>

#include "joint_tree.h"
#include "scene_runner.h"

namespace tumble::testing {
namespace {

struct Outcome {
  std::uint64_t hash = 0;
  std::uint64_t partial_factorings = 0;
};

Outcome run(const SceneDef& scene, int steps, bool whole) {
  JointTreeRefactorCheck::mode =
      whole ? JointTreeRefactorCheck::kWhole : JointTreeRefactorCheck::kCount;
  JointTreeRefactorCheck::partial = 0;
  World world = build(scene);
  for (int k = 0; k < steps; ++k)
    EXPECT_TRUE(world.step(scene.dt).is_ok()) << "step " << k;
  JointTreeRefactorCheck::mode = JointTreeRefactorCheck::kOff;
  return {state_hash(world), JointTreeRefactorCheck::partial.load()};
}

void expect_partial_equals_whole(const SceneDef& scene, int steps) {
  const Outcome partial = run(scene, steps, false);
  const Outcome whole = run(scene, steps, true);
  EXPECT_GT(partial.partial_factorings, 0u) << "the partial path never ran";
  EXPECT_EQ(whole.partial_factorings, partial.partial_factorings);
  EXPECT_EQ(whole.hash, partial.hash);
}

BodyDef bar(const Vec3& from, const Vec3& to, double mass) {
  BodyDef def;
  const double length = (to - from).norm();
  def.shape = BoxDef{Vec3(0.5 * length, 0.03, 0.03)};
  def.position = 0.5 * (from + to);
  def.orientation = Quat::FromTwoVectors(Vec3::UnitX(), to - from);
  def.mass = mass;
  return def;
}

// Released level from a fixed point: a trunk of five ball-jointed links, then a crossbar (the hub)
// holding three branches of four links whose last is a hundred times heavier: of balls, of
// hinges, and a fixed joint then balls.
SceneDef mobile_scene() {
  SceneDef scene;
  scene.name = "mobile";
  scene.world.threads = 1;
  scene.world.solver.sleeping = false;
  const auto joint = [&](JointKind kind, const Vec3& anchor, std::size_t a,
                         std::optional<std::size_t> b, const Vec3& axis = Vec3::UnitZ()) {
    SceneJoint j;
    j.def.kind = kind;
    j.def.anchor = anchor;
    j.def.axis = axis;
    j.a = a;
    j.b = b;
    scene.joints.push_back(j);
  };
  Vec3 at(0, 0, 5);
  std::optional<std::size_t> previous;
  for (int i = 0; i < 5; ++i) {
    scene.bodies.push_back(bar(at, at + Vec3(0.2, 0, 0), 0.5));
    joint(JointKind::kBall, at, scene.bodies.size() - 1, previous);
    previous = scene.bodies.size() - 1;
    at += Vec3(0.2, 0, 0);
  }
  scene.bodies.push_back(bar(at, at + Vec3(0.4, 0, 0), 1));
  joint(JointKind::kBall, at, scene.bodies.size() - 1, previous);
  const std::size_t crossbar = scene.bodies.size() - 1;
  const struct {
    Vec3 root, direction;
    JointKind first, rest;
  } branches[] = {{at + Vec3(0.1, 0, 0), Vec3::UnitY(), JointKind::kBall, JointKind::kBall},
                  {at + Vec3(0.25, 0, 0), -Vec3::UnitY(), JointKind::kHinge, JointKind::kHinge},
                  {at + Vec3(0.4, 0, 0), Vec3::UnitX(), JointKind::kFixed, JointKind::kBall}};
  for (const auto& branch : branches) {
    std::size_t parent = crossbar;
    const Vec3 axis = branch.direction.cross(Vec3::UnitZ());  // the hinges swing it down
    for (int i = 0; i < 4; ++i) {
      const Vec3 from = branch.root + 0.2 * i * branch.direction;
      scene.bodies.push_back(bar(from, from + 0.2 * branch.direction, i == 3 ? 50 : 0.5));
      joint(i == 0 ? branch.first : branch.rest, from, scene.bodies.size() - 1, parent, axis);
      parent = scene.bodies.size() - 1;
    }
  }
  return scene;
}

TEST(JointTreeRefactor, AHeavyEndedChainGetsTheBitsOfAWholeFactoring) {
  SceneDef scene = chain_scene(20, 1000);
  scene.world.threads = 1;
  expect_partial_equals_whole(scene, 120);
}

TEST(JointTreeRefactor, AChainOfAHundredLinksGetsTheBitsOfAWholeFactoring) {
  SceneDef scene = chain_scene(100);
  scene.world.threads = 1;
  expect_partial_equals_whole(scene, 300);
}

TEST(JointTreeRefactor, ABranchingMobileGetsTheBitsOfAWholeFactoring) {
  expect_partial_equals_whole(mobile_scene(), 240);
}

}  // namespace
}  // namespace tumble::testing
