// The exact solve of an island with joints: its contacts and its joints' one-sided limits and
// cones as one linear complementarity problem (exact_solver.h's, solved by Lemke's algorithm),
// and the joints' own rows held exactly alongside through the direct solve of their tree
// (joint_tree.h). The rows are not added to the LCP as equalities: each of its rows sees the
// island through the joints, its impulse's response being the tree's solve with that impulse on
// the bodies (every joint's rates unchanged), so the LCP's matrix is J S J^T with S the tree's
// constrained mobility: the contacts' Delassus matrix in the joints' null space, the mixed LCP's
// equalities eliminated by their Schur complement (Cottle, Pang and Stone 1992, ch. 1; as ODE's
// dWorldStep solves a mixed LCP, but with the equalities eliminated in linear time). Where its
// contacts act on jointed bodies the step (step.cc) holds the joints at rate zero in the tree's
// solve and relaxes each substep after its move, as the soft recipe does (without, a chain
// swinging into itself gained energy: docs/DYNAMICS.md, "Exact with joints").
#pragma once

#include <span>

#include "exact_solver.h"
#include "joint_solver.h"
#include "joint_tree.h"

namespace tumble {

// With `tree` holding the island's joints and its velocity factors current (solve_velocities has
// just given the bodies velocities that hold every joint at this substep's targets, the drives
// already swept): the contacts `ids` (separations of the substep) and the joints' limits and cones
// over a move of h, exactly. On success the bodies' velocities, the contacts' and joints'
// impulses (limits and cones kept as the joints', the joints' own rows' added) and the push-out's
// pseudo-velocities are set; on failure nothing is changed.
ExactSolveResult solve_island_exact(std::span<ContactRow> rows,
                                    std::span<const ContactRowCold> cold,
                                    std::span<const std::uint32_t> ids,
                                    std::span<JointRow> joint_rows,
                                    std::span<const std::uint32_t> joints, JointTree& tree,
                                    std::span<SolverBody> bodies, std::span<const Pose> poses,
                                    const SolverSettings& settings, double h);

}  // namespace tumble
