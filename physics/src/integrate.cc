#include "integrate.h"

#include <algorithm>
#include <cmath>

#include "rotation.h"

namespace tumble {
namespace {

Mat3 skew(const Vec3& v) {
  Mat3 m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// Solves I (w1 - w0) + h wm x (I wm) = 0 with wm = (w0 + w1) / 2, body axes.
bool gyroscopic_midpoint(const Mat3& inertia, const Vec3& w0, double h, Vec3* w1) {
  Vec3 w = w0;
  const double tolerance = 1e-13 * (w0.norm() + 1e-300);
  for (int iteration = 0; iteration < kGyroscopicIterations; ++iteration) {
    const Vec3 mid = 0.5 * (w0 + w);
    const Vec3 momentum = inertia * mid;
    const Vec3 f = inertia * (w - w0) + h * mid.cross(momentum);
    const Mat3 jacobian = inertia + 0.5 * h * (skew(mid) * inertia - skew(momentum));
    const Vec3 step = jacobian.partialPivLu().solve(f);
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

bool integrate_velocity(const Body& body, const Quat& orientation, const Vec3& gravity, double h,
                        SolverBody* state) {
  if (body.is_static()) return true;
  state->v += h * gravity;
  if (body.spherical_inertia || state->w.isZero(0)) return true;
  const Mat3 rotation = orientation.toRotationMatrix();
  const Vec3 w_start = rotation.transpose() * state->w;
  // Newton converges from the old velocity only while the body turns little in the solve; a fast
  // spinner (300 rad/s at dt 1/60 turns 5 rad a step) is advanced in pieces of at most
  // kGyroscopicMaxTurn each. Every piece keeps both invariants, so the pieces do too.
  const double turn = h * w_start.norm();
  if (!(turn <= kGyroscopicMaxTurn * kGyroscopicMaxPieces)) return false;  // w kept as it was
  const int pieces = std::max(1, static_cast<int>(std::ceil(turn / kGyroscopicMaxTurn)));
  Vec3 w_body = w_start;
  for (int piece = 0; piece < pieces; ++piece) {
    Vec3 next;
    // An unconverged answer is not used: the body keeps its body-frame spin, which loses the
    // precession of this step but keeps energy and |L| exactly.
    if (!gyroscopic_midpoint(body.inertia_body, w_body, h / pieces, &next)) return false;
    w_body = next;
  }
  state->w = rotation * w_body;
  return true;
}

void integrate_position(double h, SolverBody* state, Pose* pose) {
  if (state->inverse_mass == 0) return;
  const Vec3 dx = h * (state->v + state->push_v);
  pose->position += dx;
  state->delta_position += dx;
  const Vec3 angle = h * (state->w + state->push_w);
  const Quat turn = rotation_quaternion(angle);
  pose->orientation = (turn * pose->orientation).normalized();
  state->delta_angle += angle;
  state->push_v.setZero();
  state->push_w.setZero();
}

}  // namespace tumble
