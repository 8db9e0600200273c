// The rough arctangent behind the joints' bound decisions (physics/src/rough_atan2.h): within its
// stated bound of std::atan2 everywhere, with atan2's signs, and never the reason a decision
// differs from the exact angle's.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "joint_geometry.h"
#include "rough_atan2.h"

namespace tumble {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(RoughAngles, Atan2IsWithinItsBoundAtEveryAngleAndScale) {
  double worst = 0;
  for (double radius : {1e-300, 1e-8, 1.0, 1e8, 1e300}) {
    for (int k = -200000; k <= 200000; ++k) {
      const double angle = kPi * k / 200000.0;
      const double y = radius * std::sin(angle), x = radius * std::cos(angle);
      worst = std::max(worst, std::abs(rough_atan2(y, x) - std::atan2(y, x)));
    }
  }
  EXPECT_LT(worst, 1.2e-5);
  EXPECT_GT(worst, 1e-7);  // it is rough: a decision near a threshold must take the exact angle
  EXPECT_GE(kRoughAngleMargin, 8 * worst);
}

TEST(RoughAngles, Atan2KeepsTheSignsOfZeroAndRefusesTheNonFinite) {
  for (double y : {0.0, -0.0})
    for (double x : {0.0, -0.0, 1.0, -1.0}) {
      const double exact = std::atan2(y, x), rough = rough_atan2(y, x);
      EXPECT_EQ(rough, exact) << y << " " << x;
      EXPECT_EQ(std::signbit(rough), std::signbit(exact)) << y << " " << x;
    }
  EXPECT_DOUBLE_EQ(rough_atan2(1, 0), kPi / 2);
  EXPECT_DOUBLE_EQ(rough_atan2(-1, -0.0), -kPi / 2);
  const double inf = std::numeric_limits<double>::infinity();
  for (const auto& [y, x] : {std::pair{inf, 1.0}, std::pair{1.0, -inf},
                             std::pair{std::nan(""), 0.0}, std::pair{0.0, std::nan("")}})
    EXPECT_TRUE(std::isnan(rough_atan2(y, x)));
}

// Random relative turns of a hinge and of a ball with a cone and a twist limit, many within a
// hair of their bounds: wherever the rough test calls a pose clearly within a bound (widened by a
// slack, as the position passes ask), the exact angle is within it too.
TEST(RoughAngles, ClearlyWithinIsNeverWrong) {
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> unit(-1, 1);
  auto random_turn = [&] {
    Quat q(unit(random), unit(random), unit(random), unit(random));
    return q.normalized();
  };
  Joint hinge;
  hinge.kind = JointKind::kHinge;
  hinge.limit.enabled = true;
  hinge.limit.lower = -0.7;
  hinge.limit.upper = 1.3;
  Joint ball;
  ball.kind = JointKind::kBall;
  ball.axis_a = ball.axis_b = Vec3::UnitX();
  ball.reference_a = ball.reference_b = Vec3::UnitY();
  ball.max_swing = 0.6;
  ball.limit.enabled = true;
  ball.limit.lower = -0.4;
  ball.limit.upper = 0.5;
  int clear = 0, unclear = 0;
  for (int trial = 0; trial < 200000; ++trial) {
    const double slack = trial % 3 == 0 ? 0.0 : trial % 3 == 1 ? 1e-6 : 1e-3;
    const Quat qa = random_turn();
    // b turned from a about the hinge's axis (z) or the ball's, by an angle near a bound, and a
    // little off it.
    const double bound = (trial / 3) % 2 == 0 ? hinge.limit.lower : hinge.limit.upper;
    const double near = bound + 1e-3 * unit(random) * std::pow(10.0, -6 * std::abs(unit(random)));
    const Quat off(Eigen::AngleAxisd(1e-3 * unit(random),
                                     Vec3(unit(random), unit(random), unit(random)).normalized()));
    const Quat qb_hinge = qa * Quat(Eigen::AngleAxisd(near, Vec3::UnitZ())) * off;
    if (joint_detail::clearly_within_limit(hinge, qa, qb_hinge, slack)) {
      ++clear;
      const double angle = joint_detail::hinge_angle(hinge, qa, qb_hinge);
      EXPECT_GT(angle, hinge.limit.lower - slack);
      EXPECT_LT(angle, hinge.limit.upper + slack);
    } else {
      ++unclear;
    }
    const double lean = ball.max_swing + 1e-3 * unit(random);
    const double twist =
        (trial % 2 == 0 ? ball.limit.lower : ball.limit.upper) + 1e-4 * unit(random);
    const Quat qb_ball = qa * Quat(Eigen::AngleAxisd(lean, Vec3::UnitZ())) *
                         Quat(Eigen::AngleAxisd(twist, Vec3::UnitX()));
    if (joint_detail::clearly_within_cone(ball, qa, qb_ball, slack)) {
      const joint_detail::Swing swing = joint_detail::swing_of(ball, qa, qb_ball);
      if (swing.exists) EXPECT_LT(swing.angle, ball.max_swing + slack);
    }
    if (joint_detail::clearly_within_limit(ball, qa, qb_ball, slack)) {
      const joint_detail::FreeCoordinate c = joint_detail::free_coordinate(
          ball, Pose{Vec3::Zero(), qa}, Pose{Vec3::Zero(), qb_ball}, false);
      ASSERT_TRUE(c.exists);
      EXPECT_GT(c.position, ball.limit.lower - slack);
      EXPECT_LT(c.position, ball.limit.upper + slack);
    }
  }
  // Both answers were given: most poses are clear, those within the margin are not.
  EXPECT_GT(clear, 1000);
  EXPECT_GT(unclear, 1000);
}

// The rough free coordinates beside the exact ones over random relative turns: a hinge's angle
// and a ball's twist, within the arctangent's bound (apart on the circle: at the cut, +-pi, the
// two may fall on opposite sides).
TEST(RoughAngles, RoughCoordinatesAreWithinTheBoundOfTheExactOnes) {
  std::mt19937_64 random(11);
  std::uniform_real_distribution<double> unit(-1, 1);
  Joint ball;
  ball.kind = JointKind::kBall;
  ball.axis_a = Vec3(1, 2, 2) / 3;
  ball.axis_b = Vec3(0, 0.6, 0.8);
  ball.reference_a = Vec3(2, -1, 0).normalized();
  ball.reference_b = Vec3(1, 0, 0);
  Joint hinge = ball;
  hinge.kind = JointKind::kHinge;
  auto apart = [](double x, double y) {
    const double d = std::abs(x - y);
    return std::min(d, 2 * kPi - d);
  };
  double worst_twist = 0, worst_hinge = 0;
  for (int trial = 0; trial < 100000; ++trial) {
    const Quat qa = Quat(unit(random), unit(random), unit(random), unit(random)).normalized();
    const Quat qb = Quat(unit(random), unit(random), unit(random), unit(random)).normalized();
    const Pose pa{Vec3::Zero(), qa}, pb{Vec3::Zero(), qb};
    const joint_detail::FreeCoordinate twist = joint_detail::free_coordinate(ball, pa, pb, false);
    const double rough_twist = joint_detail::rough_coordinate_angle(ball, qa, qb);
    ASSERT_EQ(twist.exists, !std::isnan(rough_twist));
    if (twist.exists) worst_twist = std::max(worst_twist, apart(rough_twist, twist.position));
    worst_hinge = std::max(worst_hinge, apart(joint_detail::rough_coordinate_angle(hinge, qa, qb),
                                              joint_detail::hinge_angle(hinge, qa, qb)));
  }
  EXPECT_LT(worst_twist, 1.2e-5);
  EXPECT_LT(worst_hinge, 1.2e-5);
  Joint slider = hinge;
  slider.kind = JointKind::kSlider;
  EXPECT_TRUE(
      std::isnan(joint_detail::rough_coordinate_angle(slider, Quat::Identity(), Quat::Identity())));
}

}  // namespace
}  // namespace tumble
