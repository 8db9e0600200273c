// The solve of a joint's small symmetric block (a point's 3 x 3, a hinge's or a slider's 2 x 2,
// a rotation's 3 x 3), which the Gauss-Seidel sweeps repeat for every joint in every sweep.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/LU>

namespace tumble {

// Where the block has an inverse well above rounding (a joint's block is positive semidefinite,
// and definite with a moving body on either side: every joint a sweep solves), it is inverted
// once, by cofactors, and each solve is a product. Eigen's pivoted LDLT (a permutation and two
// triangular substitutions a solve, a factoring at every position pass) cost the pile of eight
// ragdolls 5.9% of its instructions with pgs and 8.6% with soft (docs/PERFORMANCE.md). Elsewhere
// (bodies that cannot move, a rank lost, a value not finite) LDLT's least-squares answer.
template <int N>
class BlockSolve {
 public:
  using Matrix = Eigen::Matrix<double, N, N>;
  using Vector = Eigen::Matrix<double, N, 1>;

  void compute(const Matrix& block) {
    const double determinant = block.determinant();
    // The determinant of a positive semidefinite block is at most (trace / N)^N; one far below
    // that is nearly singular, and its cofactors would carry the rounding: LDLT's. (The power by
    // products: std::pow with an integer exponent is libm's pow, 1.4% of the ragdoll pile's
    // instructions with pgs.)
    const double mean = block.trace() / N;
    double bound = mean;
    for (int k = 1; k < N; ++k) bound *= mean;
    invertible_ = determinant > 1e-8 * bound && block(0, 0) > 0;
    if (invertible_) {
      inverse_ = block.inverse();
    } else {
      fallback_.compute(block);
    }
  }
  Vector solve(const Vector& v) const {
    if (invertible_) return inverse_ * v;
    return fallback_.solve(v);
  }
  bool succeeded() const { return invertible_ || fallback_.info() == Eigen::Success; }
  bool inverted() const { return invertible_; }

 private:
  Matrix inverse_ = Matrix::Zero();
  Eigen::LDLT<Matrix> fallback_;
  bool invertible_ = false;
};

using BlockSolve2 = BlockSolve<2>;
using BlockSolve3 = BlockSolve<3>;

// One solve of a block not kept (the position passes' blocks, each at the poses of its pass).
template <int N>
Eigen::Matrix<double, N, 1> solve_block(const Eigen::Matrix<double, N, N>& block,
                                        const Eigen::Matrix<double, N, 1>& v) {
  BlockSolve<N> solver;
  solver.compute(block);
  return solver.solve(v);
}

// A joint point's block gains from each body -[r]x A [r]x = [r]x^T A [r]x, A the body's inverse
// inertia (symmetric) and r its lever: entry (i, j) is c_i . A c_j, where c_i = r x e_i, the
// columns of [r]x, have two entries each. Worked out from them and mirrored, that is 30 products
// where two dense 3 x 3 products were 54 (the point blocks were 4% of the ragdoll pile's
// instructions with pgs), and the block is symmetric to the bit.
inline void add_lever_inertia(const Eigen::Matrix3d& a, const Eigen::Vector3d& r,
                              Eigen::Matrix3d* block) {
  const double x = r.x(), y = r.y(), z = r.z();
  const Eigen::Vector3d a_c0 = z * a.col(1) - y * a.col(2);
  const Eigen::Vector3d a_c1 = x * a.col(2) - z * a.col(0);
  const Eigen::Vector3d a_c2 = y * a.col(0) - x * a.col(1);
  const double m00 = z * a_c0.y() - y * a_c0.z();
  const double m01 = z * a_c1.y() - y * a_c1.z();
  const double m02 = z * a_c2.y() - y * a_c2.z();
  const double m11 = x * a_c1.z() - z * a_c1.x();
  const double m12 = x * a_c2.z() - z * a_c2.x();
  const double m22 = y * a_c2.x() - x * a_c2.y();
  Eigen::Matrix3d& m = *block;
  m(0, 0) += m00;
  m(1, 1) += m11;
  m(2, 2) += m22;
  m(0, 1) += m01;
  m(1, 0) += m01;
  m(0, 2) += m02;
  m(2, 0) += m02;
  m(1, 2) += m12;
  m(2, 1) += m12;
}

}  // namespace tumble
