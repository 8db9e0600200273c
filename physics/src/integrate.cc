#include "integrate.h"

#include <algorithm>
#include <cmath>

#include "rotation.h"

namespace tumble {
namespace {

// Solves I (w1 - w0) + h wm x (I wm) = 0 with wm = (w0 + w1) / 2, body axes.
bool gyroscopic_midpoint(const Mat3& inertia, const Vec3& w0, double h, Vec3* w1) {
  Vec3 w = w0;
  const double tolerance = 1e-13 * (w0.norm() + 1e-300);
  for (int iteration = 0; iteration < kGyroscopicIterations; ++iteration) {
    const Vec3 mid = 0.5 * (w0 + w);
    const Vec3 momentum = inertia * mid;
    const Vec3 f = inertia * (w - w0) + h * mid.cross(momentum);
    // The Jacobian I + h/2 ([wm]x I - [I wm]x), column by column: column j is I's plus h/2 of
    // wm x (I e_j) - (I wm) x e_j. (Built as 3 x 3 products its temporaries went through memory
    // in pieces the loads could not forward: a tenth of a ragdoll pile's integration.)
    const double half_h = 0.5 * h;
    const Vec3 c0 = inertia.col(0) +
                    half_h * (mid.cross(inertia.col(0)) - Vec3(0, momentum.z(), -momentum.y()));
    const Vec3 c1 = inertia.col(1) +
                    half_h * (mid.cross(inertia.col(1)) - Vec3(-momentum.z(), 0, momentum.x()));
    const Vec3 c2 = inertia.col(2) +
                    half_h * (mid.cross(inertia.col(2)) - Vec3(momentum.y(), -momentum.x(), 0));
    // Cramer's rule through the columns' cross products: the rows of the inverse times the
    // determinant. The matrix is the inertia plus a small turn, far from singular, and an inexact
    // solve would only slow Newton, which stops on the step f gives; Eigen's pivoted LU was 40% of
    // the integration's instructions in a pile of ragdolls.
    const Vec3 r0 = c1.cross(c2), r1 = c2.cross(c0), r2 = c0.cross(c1);
    const double determinant = c0.dot(r0);
    if (!(std::abs(determinant) > 0)) break;
    const Vec3 step = Vec3(r0.dot(f), r1.dot(f), r2.dot(f)) / determinant;
    w -= step;
    if (step.norm() <= tolerance) {
      *w1 = w;
      return true;
    }
  }
  *w1 = w;
  return false;
}

}  // namespace

// The Cayley rotation of the rotation vector a: quaternion (1, a/2) normalised, a turn about a by
// 2 atan(|a|/2).
Quat cayley(const Vec3& a) {
  return Quat(1, 0.5 * a.x(), 0.5 * a.y(), 0.5 * a.z()).normalized();
}

bool integrate_velocity(const Body& body, const Quat& orientation, const Vec3& gravity, double h,
                        SolverBody* state) {
  if (body.is_static()) return true;
  if (!body.has_own_forces()) {
    state->v += h * gravity;
  } else {
    // The held torque acts with the world inertia of the step's start (as the contacts see it).
    state->v += h * (body.gravity_scale * gravity + body.inverse_mass * body.force);
    state->w += h * (body.inverse_inertia_world * body.torque);
    state->v /= 1 + h * body.linear_damping;
    state->w /= 1 + h * body.angular_damping;
  }
  // Without a gyroscopic torque the body turns about its constant w.
  const auto turn_about_w = [&] {
    state->free_turn = rotation_quaternion(h * state->w);
    state->w_free = state->w;
  };
  if (body.spherical_inertia || state->w.isZero(0)) {
    turn_about_w();
    return true;
  }
  const Vec3 w_start = orientation.conjugate() * state->w;
  // Newton converges from the old velocity only while the body turns little in the solve; a fast
  // spinner (300 rad/s at dt 1/60 turns 5 rad a step) is advanced in pieces of at most
  // kGyroscopicMaxTurn each. Every piece keeps both invariants, so the pieces do too.
  const double turn = h * w_start.norm();
  if (!(turn <= kGyroscopicMaxTurn * kGyroscopicMaxPieces)) {
    turn_about_w();  // w kept as it was: energy and |L| exact, this step's precession lost
    return false;
  }
  const int pieces = std::max(1, static_cast<int>(std::ceil(turn / kGyroscopicMaxTurn)));
  const double piece_h = h / pieces;
  Vec3 w_body = w_start;
  Quat body_turn = Quat::Identity();
  for (int piece = 0; piece < pieces; ++piece) {
    Vec3 next;
    // An unconverged answer is not used (as above).
    if (!gyroscopic_midpoint(body.inertia_body, w_body, piece_h, &next)) {
      turn_about_w();
      return false;
    }
    // The midpoint rule gives L1 = cay(-h wm) L0 in body axes, so turning the body by cay(h wm)
    // leaves the world momentum exactly where it was.
    body_turn = body_turn * cayley(piece_h * 0.5 * (w_body + next));
    w_body = next;
  }
  state->free_turn = (orientation * body_turn * orientation.conjugate()).normalized();
  // World axes of the body as it will be after the turn, where w_body belongs.
  state->w = orientation * (body_turn * w_body);
  state->w_free = state->w;
  return true;
}

void integrate_position(double h, SolverBody* state, Pose* pose) {
  if (state->inverse_mass == 0) return;
  const Vec3 dx = h * (state->v + state->push_v);
  pose->position += dx;
  state->delta_position += dx;
  const Vec3 angle = h * (state->w + state->push_w);
  const Quat turn = rotation_quaternion(h * (state->w - state->w_free + state->push_w));
  pose->orientation = (turn * state->free_turn * pose->orientation).normalized();
  state->delta_angle += angle;
  state->push_v.setZero();
  state->push_w.setZero();
  state->free_turn = Quat::Identity();
  state->w_free.setZero();
}

}  // namespace tumble
