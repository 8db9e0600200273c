#include "integrate.h"

#include <algorithm>
#include <cmath>

#include "rotation.h"

namespace tumble {
namespace {

// Solves I (w1 - w0) + h wm x (I wm) = 0 with wm = (w0 + w1) / 2, body axes. Written out in
// scalars, each the sum Eigen forms in the same order: Eigen takes a 3-vector as a pair and a
// single, and a pair loaded from two singles just stored waits for them to retire (store
// forwarding fails across stores): a fifth of the integration's time in a pile of ragdolls.
bool gyroscopic_midpoint(const Mat3& inertia, const Vec3& w0, double h, Vec3* w1) {
  const double i00 = inertia(0, 0), i01 = inertia(0, 1), i02 = inertia(0, 2);
  const double i10 = inertia(1, 0), i11 = inertia(1, 1), i12 = inertia(1, 2);
  const double i20 = inertia(2, 0), i21 = inertia(2, 1), i22 = inertia(2, 2);
  const double x0 = w0.x(), y0 = w0.y(), z0 = w0.z();
  double x = x0, y = y0, z = z0;
  const double tolerance = 1e-13 * (w0.norm() + 1e-300);
  const double half_h = 0.5 * h;
  for (int iteration = 0; iteration < kGyroscopicIterations; ++iteration) {
    const double mx = 0.5 * (x0 + x), my = 0.5 * (y0 + y), mz = 0.5 * (z0 + z);
    // The momentum I wm, and f = I (w - w0) + h wm x (I wm).
    const double px = i00 * mx + i01 * my + i02 * mz;
    const double py = i10 * mx + i11 * my + i12 * mz;
    const double pz = i20 * mx + i21 * my + i22 * mz;
    const double dx = x - x0, dy = y - y0, dz = z - z0;
    const double fx = (i00 * dx + i01 * dy + i02 * dz) + h * (my * pz - mz * py);
    const double fy = (i10 * dx + i11 * dy + i12 * dz) + h * (mz * px - mx * pz);
    const double fz = (i20 * dx + i21 * dy + i22 * dz) + h * (mx * py - my * px);
    // The Jacobian I + h/2 ([wm]x I - [I wm]x), column by column: column j is I's plus h/2 of
    // wm x (I e_j) - (I wm) x e_j.
    const double c0x = i00 + half_h * (my * i20 - mz * i10);
    const double c0y = i10 + half_h * ((mz * i00 - mx * i20) - pz);
    const double c0z = i20 + half_h * ((mx * i10 - my * i00) - -py);
    const double c1x = i01 + half_h * ((my * i21 - mz * i11) - -pz);
    const double c1y = i11 + half_h * (mz * i01 - mx * i21);
    const double c1z = i21 + half_h * ((mx * i11 - my * i01) - px);
    const double c2x = i02 + half_h * ((my * i22 - mz * i12) - py);
    const double c2y = i12 + half_h * ((mz * i02 - mx * i22) - -px);
    const double c2z = i22 + half_h * (mx * i12 - my * i02);
    // Cramer's rule through the columns' cross products: the rows of the inverse times the
    // determinant. The matrix is the inertia plus a small turn, far from singular, and an inexact
    // solve would only slow Newton, which stops on the step f gives; Eigen's pivoted LU was 40% of
    // the integration's instructions in a pile of ragdolls.
    const double r0x = c1y * c2z - c1z * c2y, r0y = c1z * c2x - c1x * c2z,
                 r0z = c1x * c2y - c1y * c2x;
    const double r1x = c2y * c0z - c2z * c0y, r1y = c2z * c0x - c2x * c0z,
                 r1z = c2x * c0y - c2y * c0x;
    const double r2x = c0y * c1z - c0z * c1y, r2y = c0z * c1x - c0x * c1z,
                 r2z = c0x * c1y - c0y * c1x;
    const double determinant = c0x * r0x + c0y * r0y + c0z * r0z;
    if (!(std::abs(determinant) > 0)) break;
    const double sx = (r0x * fx + r0y * fy + r0z * fz) / determinant;
    const double sy = (r1x * fx + r1y * fy + r1z * fz) / determinant;
    const double sz = (r2x * fx + r2y * fy + r2z * fz) / determinant;
    x -= sx;
    y -= sy;
    z -= sz;
    if (std::sqrt(sx * sx + sy * sy + sz * sz) <= tolerance) {
      *w1 = Vec3(x, y, z);
      return true;
    }
  }
  *w1 = Vec3(x, y, z);
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
  if (body.symmetric_spin_ratio != 0) {
    // A symmetric top in closed form: w = L / I_across + spin a, with the spin about the axis a
    // constant and L fixed, turns as a turn of w_momentum = L / I_across about L followed (in body
    // axes first) by a turn of spin about a (Landau and Lifshitz, Mechanics, sec. 33). Exact for
    // any step, so energy and world momentum stay, and no Newton or pieces: a fast spinner costs
    // what a slow one does.
    const Vec3 axis = orientation * body.symmetric_axis;
    const double spin = body.symmetric_spin_ratio * axis.dot(state->w);
    const Vec3 w_momentum = state->w - spin * axis;
    const Quat precession = rotation_quaternion(h * w_momentum);
    state->free_turn = precession * rotation_quaternion((h * spin) * axis);
    state->w = w_momentum + spin * (precession * axis);
    state->w_free = state->w;
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
