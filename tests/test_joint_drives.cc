// Joint limits, motors and springs (physics/include/physics/joint.h) and the slider: each against
// a closed-form answer (a motor's bounded acceleration, a spring's period and rest, a slide down
// an incline), bounds held at speed, stiff springs that do not blow up, the reading, and
// definitions refused naming the field.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "physics/world.h"

namespace tumble {
namespace {

constexpr double kDt = 1.0 / 60;
constexpr double kPi = std::numbers::pi;
constexpr double kG = 9.81;

BodyId add_box(World& world, const Vec3& at, const Vec3& half_extents, double mass,
               const Vec3& spin = Vec3::Zero(), const Vec3& velocity = Vec3::Zero()) {
  BodyDef def;
  def.shape = BoxDef{half_extents};
  def.position = at;
  def.mass = mass;
  def.angular_velocity = spin;
  def.linear_velocity = velocity;
  return world.create_body(def).value();
}

JointId joint(World& world, const JointDef& def) {
  Result<JointId> id = world.create_joint(def);
  EXPECT_TRUE(id) << id.status().message();
  return id ? id.value() : JointId{};
}

double position(const World& world, JointId id) {
  return world.joint_reading(id).value().position;
}
double speed(const World& world, JointId id) {
  return world.joint_reading(id).value().speed;
}

// A square plate turning about z through its centre (gravity gives it no torque): I = m (1+1)/12.
constexpr double kPlateInertia = 1.0 / 6;

JointDef plate_hinge(World& world, const Vec3& spin = Vec3::Zero()) {
  JointDef def;
  def.kind = JointKind::kHinge;
  def.a = add_box(world, Vec3(0, 0, 5), Vec3(0.5, 0.5, 0.1), 1, spin);
  def.anchor = Vec3(0, 0, 5);
  def.axis = Vec3::UnitZ();
  return def;
}

TEST(JointDrives, HingeMotorAcceleratesAtItsTorqueBoundThenHoldsItsSpeed) {
  World world;
  JointDef def = plate_hinge(world);
  def.motor = {true, 10.0, 0.5};  // 0.5 N m on I = 1/6: 3 rad/s^2 until 10 rad/s
  const JointId id = joint(world, def);
  for (int i = 0; i < 60; ++i)
    ASSERT_TRUE(world.step(kDt));
  EXPECT_NEAR(speed(world, id), 3.0, 3.0 * 1e-3);
  EXPECT_NEAR(world.joint_reading(id).value().effort, 0.5, 0.5 * 1e-3);
  for (int i = 0; i < 180; ++i)
    ASSERT_TRUE(world.step(kDt));
  EXPECT_NEAR(speed(world, id), 10.0, 1e-6);
  // Changed while running: the motor turns it back at the bound.
  ASSERT_TRUE(world.set_joint_motor(id, {true, -10.0, 0.5}));
  for (int i = 0; i < 60; ++i)
    ASSERT_TRUE(world.step(kDt));
  EXPECT_NEAR(speed(world, id), 7.0, 7.0 * 1e-3);
  EXPECT_FALSE(world.set_joint_motor(id, {true, 1.0, -1.0}));
  // Beyond the world's angular speed limit (1e6 rad/s): refused, the motor as it was.
  EXPECT_EQ(world.set_joint_motor(id, {true, 2e6, 1.0}).message().rfind("motor.speed:", 0), 0u);
  EXPECT_EQ(world.joint_def(id).value().motor.speed, -10.0);
  EXPECT_LT(std::abs(world.joint_error(id).value()), 1e-6);
}

// Zero crossings of the hinge's angle, upward, interpolated: the mean period, and the largest
// swing after each crossing (for "never grows").
struct Swings {
  double period = 0;
  std::vector<double> amplitudes;
};

Swings measure_swings(World& world, JointId id, double seconds) {
  Swings s;
  std::vector<double> crossings;
  double last = position(world, id), time = 0, peak = 0;
  for (int i = 0; i < static_cast<int>(seconds / kDt); ++i) {
    EXPECT_TRUE(world.step(kDt));
    time += kDt;
    const double x = position(world, id);
    peak = std::max(peak, std::abs(x));
    if (last < 0 && x >= 0) {
      crossings.push_back(time - kDt * x / (x - last));
      s.amplitudes.push_back(peak);
      peak = 0;
    }
    last = x;
  }
  if (crossings.size() >= 2)
    s.period = (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
  return s;
}

TEST(JointDrives, HingeSpringSwingsAtItsPeriodAndNeverGains) {
  World world;
  JointDef def = plate_hinge(world, Vec3(0, 0, 1));
  const double stiffness = 4;
  def.spring = {true, 0.0, stiffness, 0.0};
  const JointId id = joint(world, def);
  const Swings s = measure_swings(world, id, 10);
  const double exact = 2 * kPi * std::sqrt(kPlateInertia / stiffness);
  EXPECT_NEAR(s.period, exact, exact * 2e-3);
  ASSERT_GE(s.amplitudes.size(), 5u);
  for (std::size_t i = 1; i < s.amplitudes.size(); ++i)
    EXPECT_LE(s.amplitudes[i], s.amplitudes[i - 1] * (1 + 1e-9)) << "swing " << i;
  // The implicit spring keeps 1 / (1 + (omega h)^2) of its energy a substep (h: a quarter step):
  // it loses no more than that over the swings measured (it lost 34% of its swing over 10 s at
  // 0.78 Hz: the price of a spring that stays stable however stiff).
  const double omega_h = std::sqrt(stiffness / kPlateInertia) * kDt / 4;
  const double substeps = (s.amplitudes.size() - 1) * s.period / (kDt / 4);
  const double kept = std::pow(1 + omega_h * omega_h, -substeps / 2);
  EXPECT_GT(s.amplitudes.back() / s.amplitudes.front(), kept - 0.01);
}

TEST(JointDrives, HingeLimitHoldsAFallingBarAtItsBound) {
  World world;
  // A bar along x from a pivot at the origin, hinged about y: gravity swings its free end down,
  // the limit stops it 0.5 rad below the horizontal (b's turn about +y is +0.5 going down).
  JointDef def;
  def.kind = JointKind::kHinge;
  def.a = add_box(world, Vec3(0.5, 0, 5), Vec3(0.5, 0.05, 0.05), 1);
  def.anchor = Vec3(0, 0, 5);
  def.axis = Vec3::UnitY();
  def.limit = {true, -0.5, 0.5};
  const JointId id = joint(world, def);
  double most = 0;
  for (int i = 0; i < 180; ++i) {
    ASSERT_TRUE(world.step(kDt));
    most = std::max(most, std::abs(position(world, id)));
  }
  // a is the bar and b the world: the world turns by -angle relative to the bar.
  EXPECT_NEAR(std::abs(position(world, id)), 0.5, 1e-4);
  EXPECT_LT(most, 0.5 + 2e-3);
  // Resting on the bound, the limit carries gravity's torque about the pivot.
  const JointReading r = world.joint_reading(id).value();
  const double torque = kG * 0.5 * std::cos(0.5);
  EXPECT_NEAR(std::abs(r.effort), torque, torque * 1e-2);
  EXPECT_NEAR(r.force.norm(), kG, kG * 1e-2);
}

TEST(JointDrives, SliderSlidesDownAnInclineAsANewtonianBlockWould) {
  World world;
  const double incline = kPi / 6;
  JointDef def;
  def.kind = JointKind::kSlider;
  def.a = add_box(world, Vec3(0, 0, 10), Vec3(0.2, 0.1, 0.1), 3);
  def.anchor = Vec3(0, 0, 10);
  def.axis = Vec3(-std::cos(incline), 0, -std::sin(incline));  // a's axis, b (the world) slides
  const JointId id = joint(world, def);
  const Quat start = world.body(def.a).orientation();
  double worst = 0;
  for (int i = 0; i < 60; ++i) {
    ASSERT_TRUE(world.step(kDt));
    worst = std::max(worst, world.joint_error(id).value());
  }
  // a slides along its axis, away from the world's anchor: the offset falls as a block's on the
  // incline, a t (t + h) / 2 after the substeps' semi-implicit Euler (h: a quarter step).
  const double t = 1, exact = -0.5 * kG * std::sin(incline) * t * (t + kDt / 4);
  EXPECT_NEAR(position(world, id), exact, std::abs(exact) * 1e-9);
  EXPECT_LT(worst, 1e-6);
  EXPECT_LT(world.body(def.a).orientation().angularDistance(start), 1e-6);
}

TEST(JointDrives, HeavySliderHittingItsLimitAtSpeedStopsThere) {
  for (double speed_in : {5.0, 50.0, 500.0}) {
    World world;
    JointDef def;
    def.kind = JointKind::kSlider;
    def.a = add_box(world, Vec3(0, 0, 10), Vec3(0.5, 0.5, 0.5), 1000, Vec3::Zero(),
                    Vec3(0, 0, -speed_in));
    def.anchor = Vec3(0, 0, 10);
    def.axis = Vec3::UnitZ();
    // The offset is the world's anchor from a's along a's axis: it grows as a falls.
    def.limit = {true, -1.0, 1.0};
    const JointId id = joint(world, def);
    double most = 0;
    for (int i = 0; i < 120; ++i) {
      ASSERT_TRUE(world.step(kDt));
      most = std::max(most, position(world, id));
    }
    EXPECT_LT(most, 1.0 + 1e-3) << speed_in << " m/s";
    EXPECT_NEAR(position(world, id), 1.0, 1e-4) << speed_in << " m/s";
    EXPECT_LT(std::abs(world.body(def.a).linear_velocity().z()), 1e-3) << speed_in << " m/s";
  }
}

TEST(JointDrives, SliderMotorAndStiffSpringsStayBounded) {
  World world;
  JointDef def;
  def.kind = JointKind::kSlider;
  def.a = add_box(world, Vec3(0, 0, 10), Vec3(0.1, 0.1, 0.1), 2);
  def.anchor = Vec3(0, 0, 10);
  def.axis = Vec3::UnitX();
  def.motor = {true, 1.5, 100.0};
  const JointId motor = joint(world, def);
  // Springs from 1 N/m to 1e12 N/m on a body of 1 g: the implicit row rests at the target
  // (gravity's pull over the stiffness away) and never blows up.
  std::vector<std::pair<JointId, double>> springs;
  for (double stiffness : {1.0, 1e4, 1e8, 1e12}) {
    JointDef s;
    s.kind = JointKind::kSlider;
    s.a = add_box(world, Vec3(springs.size() * 2.0 + 2, 0, 10), Vec3(0.05, 0.05, 0.05), 1e-3);
    s.anchor = world.body(s.a).position();
    s.axis = Vec3::UnitZ();
    s.spring = {true, 0.0, stiffness, 2 * std::sqrt(stiffness * 1e-3)};
    springs.emplace_back(joint(world, s), stiffness);
  }
  for (int i = 0; i < 600; ++i)
    ASSERT_TRUE(world.step(kDt));
  EXPECT_NEAR(speed(world, motor), 1.5, 1e-9);
  for (const auto& [id, stiffness] : springs) {
    const double rest = 1e-3 * kG / stiffness;  // a sags, so the offset rises by this
    EXPECT_NEAR(position(world, id), rest, std::max(rest * 1e-2, 1e-9)) << stiffness;
    EXPECT_LT(std::abs(speed(world, id)), 1e-6) << stiffness;
  }
}

TEST(JointDrives, RopeAndSpringDistanceJoints) {
  World world;
  // A rope of 1 m: the ball falls freely for half a metre, then hangs at the rope's end.
  JointDef rope;
  rope.kind = JointKind::kDistance;
  rope.a = add_box(world, Vec3(0, 0, 9.5), Vec3(0.05, 0.05, 0.05), 1);
  rope.anchor = Vec3(0, 0, 9.5);
  rope.anchor_b = Vec3(0, 0, 10);
  rope.limit = {true, 0.0, 1.0};
  const JointId rope_id = joint(world, rope);
  double longest = 0;
  const double free_fall = std::sqrt(2 * 0.5 / kG);
  for (int i = 0; i < 240; ++i) {
    ASSERT_TRUE(world.step(kDt));
    longest = std::max(longest, position(world, rope_id));
    const double t = (i + 1) * kDt;
    if (t < free_fall - kDt)  // slack: the ball falls freely (the substeps' semi-implicit Euler)
      EXPECT_NEAR(world.body(rope.a).position().z(), 9.5 - 0.5 * kG * t * (t + kDt / 4), 1e-9);
  }
  EXPECT_LT(longest, 1.0 + 2e-3);
  EXPECT_NEAR(position(world, rope_id), 1.0, 1e-4);
  EXPECT_NEAR(world.joint_reading(rope_id).value().effort, -kG, kG * 1e-2);

  // A 2 kg weight on a spring of 200 N/m resting at 1 m: it bobs about 1 m + m g / k with the
  // period 2 pi sqrt(m / k).
  World bob_world;
  JointDef spring;
  spring.kind = JointKind::kDistance;
  spring.a = add_box(bob_world, Vec3(0, 0, 9), Vec3(0.05, 0.05, 0.05), 2);
  spring.anchor = Vec3(0, 0, 9);
  spring.anchor_b = Vec3(0, 0, 10);
  spring.spring = {true, 0.0, 200.0, 0.0};
  const JointId spring_id = joint(bob_world, spring);
  std::vector<double> crossings;
  const double rest = 1 + 2 * kG / 200;
  double last = position(bob_world, spring_id) - rest, time = 0, sum = 0;
  int count = 0;
  for (int i = 0; i < 600; ++i) {
    ASSERT_TRUE(bob_world.step(kDt));
    time += kDt;
    const double x = position(bob_world, spring_id) - rest;
    sum += x;
    ++count;
    if (last < 0 && x >= 0) crossings.push_back(time - kDt * x / (x - last));
    last = x;
  }
  ASSERT_GE(crossings.size(), 10u);
  const double period = (crossings.back() - crossings.front()) / (crossings.size() - 1.0);
  const double exact = 2 * kPi * std::sqrt(2.0 / 200);
  EXPECT_NEAR(period, exact, exact * 2e-3);
  EXPECT_NEAR(sum / count, 0.0, 3e-3);  // the mean stretch (whole swings and a part)
}

TEST(JointDrives, BallConeAndTwistBoundAFlungRod) {
  World world;
  // A rod hanging from a ball joint at its top, flung sideways and spun about its length.
  JointDef def;
  def.kind = JointKind::kBall;
  def.a = add_box(world, Vec3(0, 0, 9.5), Vec3(0.05, 0.05, 0.5), 1, Vec3(6, 0, 8));
  def.anchor = Vec3(0, 0, 10);
  def.axis = -Vec3::UnitZ();
  def.max_swing = 0.3;
  def.limit = {true, -0.2, 0.2};
  const JointId id = joint(world, def);
  double lean = 0, twist = 0, worst = 0;
  for (int i = 0; i < 240; ++i) {
    ASSERT_TRUE(world.step(kDt));
    const Vec3 along = world.body(def.a).orientation() * -Vec3::UnitZ();
    lean = std::max(lean, std::acos(std::clamp(along.dot(-Vec3::UnitZ()), -1.0, 1.0)));
    twist = std::max(twist, std::abs(position(world, id)));
    worst = std::max(worst, world.joint_error(id).value());
  }
  EXPECT_LT(lean, 0.3 + 5e-3);
  EXPECT_GT(lean, 0.25);  // it did reach the cone
  EXPECT_LT(twist, 0.2 + 5e-3);
  EXPECT_GT(twist, 0.15);
  EXPECT_LT(worst, 5e-3);
}

TEST(JointDrives, DefinitionsAreRefusedNamingTheField) {
  World world;
  const BodyId body = add_box(world, Vec3(0, 0, 1), Vec3(0.1, 0.1, 0.1), 1);
  auto refused = [&](JointDef def, const std::string& field) {
    def.a = body;
    const Result<JointId> id = world.create_joint(def);
    ASSERT_FALSE(id) << field;
    EXPECT_EQ(id.status().message().rfind(field, 0), 0u) << id.status().message();
  };
  JointDef def;
  def.kind = JointKind::kBall;
  def.motor = {true, 1, 1};
  refused(def, "motor");
  def = {};
  def.kind = JointKind::kFixed;
  def.limit = {true, 0, 1};
  refused(def, "limit");
  def = {};
  def.kind = JointKind::kHinge;
  def.limit = {true, 1, -1};
  refused(def, "limit");
  def.limit = {true, -4, 0};
  refused(def, "limit");
  def = {};
  def.kind = JointKind::kHinge;
  def.max_swing = 1;
  refused(def, "max_swing");
  def = {};
  def.kind = JointKind::kSlider;
  def.axis = Vec3::Zero();
  refused(def, "axis");
  def = {};
  def.kind = JointKind::kSlider;
  def.spring = {true, 0, -1, 0};
  refused(def, "spring.stiffness");
  def.spring = {true, 0, 0, 0};
  refused(def, "spring");
  def = {};
  def.kind = JointKind::kDistance;
  def.anchor_b = Vec3(0, 0, 2);
  def.spring = {true, 0.5, 1, 0};
  refused(def, "spring.target");
  def = {};
  def.kind = JointKind::kHinge;
  def.motor = {true, std::nan(""), 1};
  refused(def, "motor.speed");
  def = {};
  def.kind = JointKind::kBall;
  def.limit = {true, -0.1, 0.1};
  refused(def, "limit");  // a twist needs a cone
  EXPECT_EQ(world.joint_count(), 0u);
  // A running joint's drive is checked for its kind.
  JointDef ball;
  ball.a = body;
  const JointId id = world.create_joint(ball).value();
  EXPECT_EQ(world.set_joint_spring(id, {true, 0, 1, 1}).message().rfind("spring", 0), 0u);
  EXPECT_FALSE(world.set_joint_motor(JointId{}, {}));
}

}  // namespace
}  // namespace tumble
