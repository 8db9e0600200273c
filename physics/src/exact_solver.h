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

struct ExactSolveResult {
  LemkeResult lemke;
  bool solved() const { return lemke.outcome == LemkeOutcome::kSolved; }
};

// Solves the island's rows over a step h and applies the impulses to `bodies` on success; on
// failure nothing is changed.
ExactSolveResult solve_contacts_exact(std::span<ContactRow> rows,
                                      std::span<const std::uint32_t> ids,
                                      std::span<SolverBody> bodies, const SolverSettings& settings,
                                      double h);

}  // namespace tumble
