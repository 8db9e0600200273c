// The exact contact solver: every contact of an island at once, as one linear complementarity
// problem with Coulomb friction on a polyhedral cone, solved by Lemke's algorithm.
//
// Formulation after Stewart and Trinkle (1996) and Anitescu and Potra (1997): per contact point
// a normal impulse cn, impulses b_j >= 0 along k directions spanning the tangent plane, and a
// multiplier l (the sliding speed):
//   v_n(+) - target  >= 0  _|_  cn >= 0
//   v_j(+) + l       >= 0  _|_  b_j >= 0
//   mu cn - sum_j b_j >= 0  _|_  l >= 0
// with v(+) the velocities after the impulses. The friction cone is the polygon with k vertices
// mu cn d_j; its first direction is the sliding direction, where the polygon touches the circle.
#pragma once

#include <span>

#include "contact_solver.h"
#include "lemke.h"

namespace tumble {

// Proximal-point passes allowed when the regularised answer misses exact_velocity_tolerance.
constexpr int kExactRefinements = 3;

struct ExactSolveResult {
  LemkeResult lemke;
  // The largest velocity error of the accepted answer (m/s; exact_velocity_error).
  double velocity_error = 0;
  // Penetration was pushed out (or there was none); false leaves it to position correction.
  bool pushed_out = false;
  bool solved() const { return lemke.outcome == LemkeOutcome::kSolved; }
};

// How far an LCP answer z is from right, in m/s: the worst violation of w = M z + q >= 0 and of
// its complementarity with z, over the velocity rows with M's true diagonal `diagonal` (M itself
// may be regularised) and over the friction-cone rows that follow them, whose impulses are made
// velocities by the stiffness of their point's normal row.
double exact_velocity_error(const Eigen::Ref<const Eigen::MatrixXd>& m,
                            std::span<const double> diagonal,
                            const Eigen::Ref<const Eigen::VectorXd>& q,
                            const Eigen::Ref<const Eigen::VectorXd>& z, int velocity_rows);

// Solves the island's rows over a step h and applies the impulses to `bodies` on success; on
// failure nothing is changed. An answer whose velocity error exceeds
// settings.exact_velocity_tolerance is a failure (kInaccurate). On success, penetration is
// pushed out through the bodies' pseudo-velocities (push_v, push_w), not their velocities.
ExactSolveResult solve_contacts_exact(std::span<ContactRow> rows,
                                      std::span<const ContactRowCold> cold,
                                      std::span<const std::uint32_t> ids,
                                      std::span<SolverBody> bodies, const SolverSettings& settings,
                                      double h);

}  // namespace tumble
