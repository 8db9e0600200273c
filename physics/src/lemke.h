// Lemke's complementary pivoting algorithm for the linear complementarity problem
//   w = M z + q,  w >= 0,  z >= 0,  w . z = 0
// (Lemke 1965; Cottle, Pang and Stone, "The Linear Complementarity Problem", 1992, ch. 4).
// Degenerate pivots are ordered lexicographically, so the algorithm cannot cycle.
#pragma once

#include <Eigen/Dense>
#include <cstdint>

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

// Solves into `z` (resized to q's size). `max_pivots` bounds the work.
LemkeResult solve_lcp_lemke(const Eigen::MatrixXd& m, const Eigen::VectorXd& q, int max_pivots,
                            Eigen::VectorXd* z);

}  // namespace tumble
