// Time integration of one body: symplectic Euler with an implicit-midpoint gyroscopic step.
#pragma once

#include "contact_solver.h"
#include "physics/body.h"

namespace tumble {

// Newton iterations allowed for the gyroscopic step; it converges in 2-3 for any sane spin.
constexpr int kGyroscopicIterations = 8;

// Velocities over h: gravity, then the free rotation of Euler's equations in body axes by the
// implicit midpoint rule, which keeps kinetic energy and |L| of a free body exactly (both are
// quadratic invariants, Hairer-Lubich-Wanner ch. IV). Returns false when Newton hit its bound.
bool integrate_velocity(const Body& body, const Quat& orientation, const Vec3& gravity, double h,
                        SolverBody* state);

// Positions over h with the new velocities; the rotation is the exact exponential of w h.
void integrate_position(double h, SolverBody* state, Pose* pose);

}  // namespace tumble
