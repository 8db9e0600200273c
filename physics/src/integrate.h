// Time integration of one body: symplectic Euler with an implicit-midpoint gyroscopic step (a
// symmetric top's free rotation in closed form).
#pragma once

#include "body_state.h"
#include "contact_solver.h"

namespace tumble {

// Newton iterations allowed for the gyroscopic step; it converges in 2-3 while the body turns
// by at most kGyroscopicMaxTurn (rad) in the solve, so a step is split into pieces that turn no
// more than that, at most kGyroscopicMaxPieces of them (10^4 rad/s at dt 1/30 needs 667).
constexpr int kGyroscopicIterations = 8;
constexpr double kGyroscopicMaxTurn = 0.5;
constexpr int kGyroscopicMaxPieces = 1024;

// Velocities over h: gravity (scaled by the body's gravity_scale), its held force and torque and
// its damping (implicit: v / (1 + c h)), then the free rotation of Euler's equations in body axes
// by the implicit midpoint rule, which keeps kinetic energy and |L| of a free body exactly (both
// are quadratic invariants, Hairer-Lubich-Wanner ch. IV); a symmetric top (Body::symmetric_axis)
// takes its exact free rotation instead, and never fails. Returns false when Newton hit its bound
// or the spin needs more pieces than allowed; the body then keeps its body-frame angular
// velocity for the step (energy and |L| still exact), and the step counts it. Either way it
// prepares state->free_turn and w_free for integrate_position.
bool integrate_velocity(const Body& body, const Quat& orientation, const Vec3& gravity, double h,
                        SolverBody* state);

// Positions over h with the new velocities and any push-out pseudo-velocities (used once, then
// cleared). The body turns by the free rotation integrate_velocity prepared and by the exact
// exponential of whatever the contacts changed in w. The free rotation of a body with a
// gyroscopic torque is the product of its pieces' Cayley rotations cay(h wm): with the midpoint
// rule's L1 = cay(-h wm) L0 in body axes, that keeps the world angular momentum of a free body
// exactly (the Lie-Poisson midpoint integrator; Austin, Krishnaprasad and Wang 1993), as well as
// its energy and |L|. Turning about w1 instead, as before, let the world L turn by O(h) a step.
void integrate_position(double h, SolverBody* state, Pose* pose);

}  // namespace tumble
