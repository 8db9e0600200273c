// The solve of a joint's small symmetric block (a point's 3 x 3, a hinge's or a slider's 2 x 2,
// a rotation's 3 x 3), which the Gauss-Seidel sweeps repeat for every joint in every sweep.
#pragma once

#include <cmath>

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
    // (The determinant of a positive semidefinite block is at most (trace / N)^N; one far below
    // that is nearly singular, and its cofactors would carry the rounding: LDLT's.)
    invertible_ = determinant > 1e-8 * std::pow(block.trace() / N, N) && block(0, 0) > 0;
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

}  // namespace tumble
