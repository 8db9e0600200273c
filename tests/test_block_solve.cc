// The Gauss-Seidel joints' small block solves (physics/src/block_solve.h): the inverse where the
// block is positive definite agrees with a pivoted LDLT to rounding over the blocks the joints
// make, and every other block (bodies that cannot move, a rank lost, a value not finite) gets
// LDLT's answer, bit for bit; and the point block's lever terms, worked out entry by entry, are
// the dense product's to rounding.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>

#include "block_solve.h"

namespace tumble {
namespace {

using Mat3 = Eigen::Matrix3d;
using Vec3 = Eigen::Vector3d;

// One body's side of a joint: masses and inertias over six orders of magnitude, levers from a
// millimetre to 10 m.
struct JointSide {
  double inverse_mass;
  Mat3 inverse_inertia;
  Vec3 lever;
  // [r]x W [r]x^T, as two dense products.
  Mat3 dense_lever_term() const {
    Mat3 cross;
    cross << 0, -lever.z(), lever.y(), lever.z(), 0, -lever.x(), -lever.y(), lever.x(), 0;
    return cross * inverse_inertia * cross.transpose();
  }
};

JointSide random_side(std::mt19937_64& random) {
  std::uniform_real_distribution<double> exponent(-3, 3), unit(-1, 1);
  JointSide side;
  side.inverse_mass = std::pow(10.0, exponent(random));
  const Eigen::Quaterniond turn =
      Eigen::Quaterniond(unit(random), unit(random), unit(random), unit(random)).normalized();
  const Vec3 moments(std::pow(10.0, exponent(random)), std::pow(10.0, exponent(random)),
                     std::pow(10.0, exponent(random)));
  side.inverse_inertia =
      turn.toRotationMatrix() * moments.asDiagonal() * turn.toRotationMatrix().transpose();
  side.lever =
      Vec3(unit(random), unit(random), unit(random)) * std::pow(10.0, exponent(random) / 3 - 1);
  return side;
}

// A point's block as a joint makes it: (1/m_a + 1/m_b) 1 + [r_a]x W_a [r_a]x^T + ...
Mat3 point_block(std::mt19937_64& random) {
  Mat3 block = Mat3::Zero();
  for (int k = 0; k < 2; ++k) {
    const JointSide side = random_side(random);
    block += side.inverse_mass * Mat3::Identity() + side.dense_lever_term();
  }
  return block;
}

TEST(BlockSolve, InverseAgreesWithLdltOnJointBlocksToRounding) {
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> unit(-1, 1);
  double worst = 0;
  int inverted = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const Mat3 block = point_block(random);
    const Vec3 v(unit(random), unit(random), unit(random));
    BlockSolve3 solver;
    solver.compute(block);
    ASSERT_TRUE(solver.succeeded());
    inverted += solver.inverted() ? 1 : 0;
    const Vec3 ours = solver.solve(v), reference = block.ldlt().solve(v);
    // Relative to the answer's scale: both are backward stable; their difference is the block's
    // condition times rounding, and the blocks here stay far from singular.
    worst = std::max(worst, (ours - reference).norm() / reference.norm());
    EXPECT_LT((block * ours - v).norm(), 1e-12 * block.norm() * ours.norm());
  }
  EXPECT_LT(worst, 1e-8);
  EXPECT_EQ(inverted, 20000);  // a joint's block with a moving body is never left to LDLT
}

TEST(BlockSolve, BlocksWithoutAnInverseTakeLdltsAnswer) {
  const Vec3 v(0.3, -1.2, 2.5);
  Mat3 rank_two = Mat3::Zero();
  rank_two.diagonal() << 2, 3, 0;
  Mat3 nearly = Mat3::Identity();
  nearly(2, 2) = 1e-12;  // positive, but beyond the margin the inverse is taken within
  Mat3 not_finite = Mat3::Identity();
  not_finite(1, 1) = std::numeric_limits<double>::quiet_NaN();
  for (const Mat3& block : {Mat3(Mat3::Zero()), rank_two, nearly, not_finite}) {
    BlockSolve3 solver;
    solver.compute(block);
    const Eigen::LDLT<Mat3> reference(block);
    EXPECT_EQ(solver.succeeded(), reference.info() == Eigen::Success);
    const Vec3 ours = solver.solve(v), theirs = reference.solve(v);
    for (int i = 0; i < 3; ++i) {
      if (std::isnan(theirs[i]))
        EXPECT_TRUE(std::isnan(ours[i]));
      else
        EXPECT_EQ(ours[i], theirs[i]);
    }
  }
}

TEST(BlockSolve, LeverInertiaIsTheDenseProductAndSymmetricToTheBit) {
  std::mt19937_64 random(11);
  double worst = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const JointSide side = random_side(random);
    Mat3 ours = Mat3::Zero();
    add_lever_inertia(side.inverse_inertia, side.lever, &ours);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) EXPECT_EQ(ours(i, j), ours(j, i));
    // Both sum products of the same terms in other orders: they differ by rounding at the scale
    // of the largest term, |A| |r|^2.
    worst = std::max(worst, (ours - side.dense_lever_term()).norm() /
                                (side.inverse_inertia.norm() * side.lever.squaredNorm()));
  }
  EXPECT_LT(worst, 1e-14);
}

TEST(BlockSolve, TwoByTwoBlocksToo) {
  Eigen::Matrix2d block;
  block << 4, 1, 1, 3;
  const Eigen::Vector2d v(1, 2);
  BlockSolve2 solver;
  solver.compute(block);
  EXPECT_LT((solver.solve(v) - block.ldlt().solve(v)).norm(), 1e-15);
  EXPECT_LT((block * solver.solve(v) - v).norm(), 1e-15);
}

}  // namespace
}  // namespace tumble
