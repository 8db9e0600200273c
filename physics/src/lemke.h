// Lemke's complementary pivoting algorithm for the linear complementarity problem
//   w = M z + q,  w >= 0,  z >= 0,  w . z = 0
// (Lemke 1965; Cottle, Pang and Stone, "The Linear Complementarity Problem", 1992, ch. 4).
// Degenerate pivots are ordered lexicographically, so the algorithm cannot cycle.
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <vector>

namespace tumble {

enum class LemkeOutcome : std::uint8_t {
  kSolved,
  kRayTermination,  // no solution found along the path (the problem may have none)
  kPivotLimit,      // stopped at the bound on pivots
  kNotFinite,       // a NaN or infinity in the input (or the answer)
  kInaccurate,      // set by callers that check the answer and find it off (round-off)
};

struct LemkeResult {
  LemkeOutcome outcome = LemkeOutcome::kSolved;
  int pivots = 0;
};

// Memory of the pivoting, kept by the caller so that repeated solves allocate nothing.
struct LemkeWorkspace {
  std::vector<double> basis_inverse, values, column;
  std::vector<int> basic;
};

// Solves into `z` (q's size). `max_pivots` bounds the work.
LemkeResult solve_lcp_lemke(const Eigen::Ref<const Eigen::MatrixXd>& m,
                            const Eigen::Ref<const Eigen::VectorXd>& q, int max_pivots,
                            Eigen::Ref<Eigen::VectorXd> z, LemkeWorkspace* workspace);
// The same with a workspace of its own; `z` is resized.
LemkeResult solve_lcp_lemke(const Eigen::MatrixXd& m, const Eigen::VectorXd& q, int max_pivots,
                            Eigen::VectorXd* z);

}  // namespace tumble
