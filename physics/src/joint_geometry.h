// What the joint solvers share: the two bodies of a joint row (the world as a body that never
// moves), lever arms, impulses and displacements applied through inverse masses, and a joint's
// free coordinate (joint.h) with the row that moves it. Private to the engine.
#pragma once

#include <cmath>
#include <limits>
#include <span>

#include "contact_solver.h"
#include "joint_solver.h"
#include "joint_state.h"
#include "physics/math.h"
#include "rotation.h"
#include "rough_atan2.h"

namespace tumble::joint_detail {

// The world as body b: no mass, no motion, and its own frame.
inline const SolverBody kWorldBody{};

// Any unit vector perpendicular to the unit vector n.
inline Vec3 perpendicular(const Vec3& n) {
  const Vec3 axis = std::abs(n.x()) < 0.57735 ? Vec3::UnitX() : Vec3::UnitY();
  return n.cross(axis).normalized();
}

// The two bodies of a row, velocities and poses; the world's are the origin, at rest, and never
// written. A static body (inverse mass 0) is never written either: other islands share it.
struct JointBodies {
  SolverBody* a;
  SolverBody* b;  // null for the world
  Pose pose_a;
  Pose pose_b;
  const SolverBody& body_b() const { return b != nullptr ? *b : kWorldBody; }
  bool world_b() const { return b == nullptr; }
};

inline JointBodies bodies_of(const JointRow& row, std::span<SolverBody> bodies,
                             std::span<const Pose> poses) {
  if (row.b == kWorldAnchor) return {&bodies[row.a], nullptr, poses[row.a], Pose{}};
  return {&bodies[row.a], &bodies[row.b], poses[row.a], poses[row.b]};
}

// Impulse p at the anchors (on b; a takes -p), lever arms ra and rb from the centres of mass.
inline void apply_linear(JointBodies& j, const Vec3& ra, const Vec3& rb, const Vec3& p) {
  if (j.a->inverse_mass > 0) {
    j.a->v -= j.a->inverse_mass * p;
    j.a->w -= j.a->inverse_inertia * ra.cross(p);
  }
  if (j.b != nullptr && j.b->inverse_mass > 0) {
    j.b->v += j.b->inverse_mass * p;
    j.b->w += j.b->inverse_inertia * rb.cross(p);
  }
}

// Angular impulse l on b (a takes -l).
inline void apply_angular(JointBodies& j, const Vec3& l) {
  if (j.a->inverse_mass > 0) j.a->w -= j.a->inverse_inertia * l;
  if (j.b != nullptr && j.b->inverse_mass > 0) j.b->w += j.b->inverse_inertia * l;
}

// The anchors' lever arms and world points at the given poses.
struct Anchors {
  Vec3 ra, rb, pa, pb;
};

inline Anchors anchors_of(const Joint& joint, const Pose& pose_a, const Pose& pose_b,
                          bool world_b) {
  Anchors anchors;
  anchors.ra = pose_a.orientation * joint.local_a;
  anchors.pa = pose_a.position + anchors.ra;
  if (world_b) {
    anchors.pb = joint.local_b;
    anchors.rb = Vec3::Zero();
  } else {
    anchors.rb = pose_b.orientation * joint.local_b;
    anchors.pb = pose_b.position + anchors.rb;
  }
  return anchors;
}

// The velocity of b's anchor relative to a's.
inline Vec3 anchor_velocity(const JointBodies& j, const Anchors& anchors) {
  const SolverBody& b = j.body_b();
  return (b.v + b.w.cross(anchors.rb)) - (j.a->v + j.a->w.cross(anchors.ra));
}

// One scalar row: its rate is linear . (v_b - v_a) + angular_a . w_a + angular_b . w_b.
struct AxialRow {
  Vec3 linear = Vec3::Zero(), angular_a = Vec3::Zero(), angular_b = Vec3::Zero();
};

// The row's effective inverse mass.
inline double row_mass(const AxialRow& row, const SolverBody& a, const SolverBody& b) {
  return (a.inverse_mass + b.inverse_mass) * row.linear.squaredNorm() +
         row.angular_a.dot(a.inverse_inertia * row.angular_a) +
         row.angular_b.dot(b.inverse_inertia * row.angular_b);
}

inline double row_rate(const AxialRow& row, const SolverBody& a, const SolverBody& b) {
  return row.linear.dot(b.v - a.v) + row.angular_a.dot(a.w) + row.angular_b.dot(b.w);
}

inline void apply_row(JointBodies& j, const AxialRow& row, double impulse) {
  if (j.a->inverse_mass > 0) {
    j.a->v -= j.a->inverse_mass * impulse * row.linear;
    j.a->w += j.a->inverse_inertia * (impulse * row.angular_a);
  }
  if (j.b != nullptr && j.b->inverse_mass > 0) {
    j.b->v += j.b->inverse_mass * impulse * row.linear;
    j.b->w += j.b->inverse_inertia * (impulse * row.angular_b);
  }
}

// Moves a body by dx and turns it by dtheta (a position pass), keeping its motion since the step
// start current for the contacts' separations. Statics and the world (null) stay.
inline void move_body(SolverBody* body, Pose* pose, const Vec3& dx, const Vec3& dtheta) {
  if (body == nullptr || body->inverse_mass == 0) return;
  pose->position += dx;
  pose->orientation = rotated(pose->orientation, dtheta);
  body->delta_position += dx;
  body->delta_angle += dtheta;
}

// Moves the bodies by `amount` along the row through their inverse masses and inertias.
inline void displace_row(const AxialRow& row, double amount, SolverBody* a, SolverBody* b,
                         Pose* pose_a, Pose* pose_b) {
  move_body(a, pose_a, -a->inverse_mass * amount * row.linear,
            a->inverse_inertia * (amount * row.angular_a));
  if (b != nullptr)
    move_body(b, pose_b, b->inverse_mass * amount * row.linear,
              b->inverse_inertia * (amount * row.angular_b));
}

// A joint's free coordinate (joint.h) at the given poses, and the row along which it changes.
// `exists` is false for fixed joints and where it has no direction (a distance joint's ends
// meeting, a ball's axes opposite).
struct FreeCoordinate {
  bool exists = false;
  double position = 0;
  AxialRow row;
};

// A hinge's angle (hinge_angle) as the sine and cosine its atan2 takes.
inline void hinge_sine_cosine(const Joint& joint, const Quat& qa, const Quat& qb, double* sine,
                              double* cosine) {
  const Vec3 axis = qa * joint.axis_a;
  const Vec3 ref_a = qa * joint.reference_a, ref_b = qb * joint.reference_b;
  *sine = axis.dot(ref_a.cross(ref_b));
  *cosine = ref_a.dot(ref_b);
}

// b's turn about the axis from a, measured between the reference directions.
inline double hinge_angle(const Joint& joint, const Quat& qa, const Quat& qb) {
  double sine = 0, cosine = 0;
  hinge_sine_cosine(joint, qa, qb, &sine, &cosine);
  return std::atan2(sine, cosine);
}

// A ball's twist (free_coordinate) as the sine and cosine its atan2 takes; false where it has
// none (the axes opposite). `mean`: the sum of the axes, about which the twist turns.
inline bool twist_sine_cosine(const Joint& joint, const Quat& qa, const Quat& qb, double* sine,
                              double* cosine, Vec3* mean) {
  const Vec3 axis_a = qa * joint.axis_a, axis_b = qb * joint.axis_b;
  *mean = axis_a + axis_b;
  if (!(mean->norm() > 1e-6)) return false;
  const Quat swing = Quat::FromTwoVectors(axis_b, axis_a);
  const Vec3 ref_a = qa * joint.reference_a, ref_b = swing * (qb * joint.reference_b);
  *sine = axis_a.dot(ref_a.cross(ref_b));
  *cosine = ref_a.dot(ref_b);
  return true;
}

inline FreeCoordinate free_coordinate(const Joint& joint, const Pose& pose_a, const Pose& pose_b,
                                      bool world_b) {
  FreeCoordinate c;
  const Quat& qa = pose_a.orientation;
  const Quat qb = world_b ? Quat::Identity() : pose_b.orientation;
  switch (joint.kind) {
    case JointKind::kFixed:
      return c;
    case JointKind::kHinge: {
      const Vec3 axis = qa * joint.axis_a;
      c.exists = true;
      c.position = hinge_angle(joint, qa, qb);
      c.row.angular_a = -axis;
      c.row.angular_b = axis;
      return c;
    }
    case JointKind::kBall: {
      // The twist: b's reference turned back by the swing that takes b's axis onto a's, measured
      // about a's axis; its rate about the axes' mean (the twist's axis halfway through the swing).
      double sine = 0, cosine = 0;
      Vec3 mean;
      if (!twist_sine_cosine(joint, qa, qb, &sine, &cosine, &mean)) return c;
      c.exists = true;
      c.position = std::atan2(sine, cosine);
      const Vec3 twist_axis = mean.normalized();
      c.row.angular_a = -twist_axis;
      c.row.angular_b = twist_axis;
      return c;
    }
    case JointKind::kSlider: {
      const Anchors anchors = anchors_of(joint, pose_a, pose_b, world_b);
      const Vec3 axis = qa * joint.axis_a;
      const Vec3 d = anchors.pb - anchors.pa;
      c.exists = true;
      c.position = d.dot(axis);
      // d/dt (d . axis) with the axis turning with a: a's lever arm reaches b's anchor.
      c.row.linear = axis;
      c.row.angular_a = -(anchors.ra + d).cross(axis);
      c.row.angular_b = anchors.rb.cross(axis);
      return c;
    }
    case JointKind::kDistance: {
      const Anchors anchors = anchors_of(joint, pose_a, pose_b, world_b);
      const Vec3 d = anchors.pb - anchors.pa;
      const double length = d.norm();
      if (!(length > 1e-12)) return c;
      const Vec3 n = d / length;
      c.exists = true;
      c.position = length;
      c.row.linear = n;
      c.row.angular_a = -anchors.ra.cross(n);
      c.row.angular_b = anchors.rb.cross(n);
      return c;
    }
  }
  return c;
}

// A ball's lean: the angle between the two axes, and the row along which it grows.
struct Swing {
  bool exists = false;
  double angle = 0;
  AxialRow row;
};

inline Swing swing_of(const Joint& joint, const Quat& qa, const Quat& qb) {
  Swing s;
  const Vec3 axis_a = qa * joint.axis_a, axis_b = qb * joint.axis_b;
  const Vec3 n = axis_a.cross(axis_b);
  const double sine = n.norm();
  if (!(sine > 1e-9)) return s;  // aligned (no lean to bound) or opposite (no direction)
  s.exists = true;
  s.angle = std::atan2(sine, axis_a.dot(axis_b));
  s.row.angular_a = -n / sine;
  s.row.angular_b = n / sine;
  return s;
}

// The free coordinate's angle of a hinge or ball to within 1.2e-5 rad (rough_atan2), for decisions
// clearly away from a limit; NaN for other joints, or where free_coordinate has none.
inline double rough_coordinate_angle(const Joint& joint, const Quat& qa, const Quat& qb) {
  double sine = 0, cosine = 0;
  Vec3 mean;
  if (joint.kind == JointKind::kHinge)
    hinge_sine_cosine(joint, qa, qb, &sine, &cosine);
  else if (joint.kind != JointKind::kBall ||
           !twist_sine_cosine(joint, qa, qb, &sine, &cosine, &mean))
    return std::numeric_limits<double>::quiet_NaN();
  return rough_atan2(sine, cosine);
}

// Whether the free coordinate is clearly within the limit widened by `slack` on both sides (by
// more than the rough angle's margin): then it is not past it by more than the slack (nor past it
// at all with no slack), as the exact angle would say. False where that takes the exact angle.
// (Angle limits lie within [-pi, pi] (joint.cc): an angle within the margin of the arctangent's
// cut at +-pi, where the rough and the exact one may fall on opposite sides, is never clearly
// within one.)
inline bool clearly_within_limit(const Joint& joint, const Quat& qa, const Quat& qb, double slack) {
  if (joint.limit.lower == joint.limit.upper) return false;  // locked: held wherever it is
  const double angle = rough_coordinate_angle(joint, qa, qb);
  return angle >= joint.limit.lower - slack + kRoughAngleMargin &&
         angle <= joint.limit.upper + slack - kRoughAngleMargin;
}

// Whether a ball's lean is clearly within its cone widened by `slack` (swing_of's angle, rough):
// also where it has no lean (swing_of: exists false), which no cone bounds.
inline bool clearly_within_cone(const Joint& joint, const Quat& qa, const Quat& qb, double slack) {
  const Vec3 axis_a = qa * joint.axis_a, axis_b = qb * joint.axis_b;
  const double sine = axis_a.cross(axis_b).norm();
  if (!(sine > 1e-9)) return true;
  return rough_atan2(sine, axis_a.dot(axis_b)) <= joint.max_swing + slack - kRoughAngleMargin;
}

// What a joint's rows do as a distance joint with neither spring nor range: a rigid rod.
inline bool rigid_distance(const Joint& joint) {
  return joint.kind == JointKind::kDistance && !joint.spring.enabled &&
         !(joint.limit.enabled && joint.limit.lower < joint.limit.upper);
}

// How far the free coordinate is outside the limit (0 inside, or without one).
inline double limit_violation(const Joint& joint, double position) {
  if (!joint.limit.enabled) return 0;
  return std::max({joint.limit.lower - position, position - joint.limit.upper, 0.0});
}

}  // namespace tumble::joint_detail
