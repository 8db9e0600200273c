#include "joint_solver.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "rotation.h"

namespace tumble {
namespace {

// The world as body b: no mass, no motion, and its own frame.
const SolverBody kWorldBody{};

// The two bodies of a row, velocities and poses; the world's are the origin, at rest, and never
// written.
struct JointBodies {
  SolverBody* a;
  SolverBody* b;  // null for the world
  const Pose& pose_a;
  Pose pose_b;
  const SolverBody& body_b() const { return b != nullptr ? *b : kWorldBody; }
};

JointBodies bodies_of(const JointRow& row, std::span<SolverBody> bodies,
                      std::span<const Pose> poses) {
  if (row.b == kWorldAnchor) return {&bodies[row.a], nullptr, poses[row.a], Pose{}};
  return {&bodies[row.a], &bodies[row.b], poses[row.a], poses[row.b]};
}

Mat3 skew(const Vec3& v) {
  Mat3 m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// Any unit vector perpendicular to the unit vector n.
Vec3 perpendicular(const Vec3& n) {
  const Vec3 axis = std::abs(n.x()) < 0.57735 ? Vec3::UnitX() : Vec3::UnitY();
  return n.cross(axis).normalized();
}

// Impulse p at the anchors (on b; a takes -p), lever arms ra and rb from the centres of mass.
// A static body (inverse mass 0, zero inertia) is never written: it may be shared with other
// islands.
void apply_linear(JointBodies& j, const Vec3& ra, const Vec3& rb, const Vec3& p) {
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
void apply_angular(JointBodies& j, const Vec3& l) {
  if (j.a->inverse_mass > 0) j.a->w -= j.a->inverse_inertia * l;
  if (j.b != nullptr && j.b->inverse_mass > 0) j.b->w += j.b->inverse_inertia * l;
}

// The anchors' lever arms and world points at the bodies' present poses.
struct Anchors {
  Vec3 ra, rb, pa, pb;
};

Anchors anchors_of(const Joint& joint, const Pose& pose_a, const Pose& pose_b, bool world_b) {
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
Vec3 anchor_velocity(const JointBodies& j, const Anchors& anchors) {
  const SolverBody& b = j.body_b();
  return (b.v + b.w.cross(anchors.rb)) - (j.a->v + j.a->w.cross(anchors.ra));
}

// How far an anchor r (from the centre of mass) moves over a move of h: the body's translation
// and its exact turn, as the move makes them.
Vec3 anchor_move(const SolverBody& body, const Vec3& r, double h) {
  return h * body.v + (rotation_quaternion(h * body.w) * r - r);
}

// A velocity for a drift over h, at most `most` long (0 without a move ahead).
Vec3 drift_velocity(const Vec3& drift, double h, double most) {
  if (!(h > 0)) return Vec3::Zero();
  const Vec3 v = drift / h;
  const double length = v.norm();
  return length > most ? Vec3(v * (most / length)) : v;
}
double drift_velocity(double drift, double h, double most) {
  if (!(h > 0)) return 0;
  return std::clamp(drift / h, -most, most);
}

// The point constraint of ball, hinge and fixed joints: three rows solved together.
double solve_point(JointRow& row, JointBodies& j, const Anchors& anchors, const JointTarget& t) {
  const SolverBody& b = j.body_b();
  const Mat3 ra_skew = skew(anchors.ra), rb_skew = skew(anchors.rb);
  const Mat3 k = (j.a->inverse_mass + b.inverse_mass) * Mat3::Identity() -
                 ra_skew * j.a->inverse_inertia * ra_skew - rb_skew * b.inverse_inertia * rb_skew;
  // The move's drift beyond the velocities' first order (the turns' curvature), which the
  // velocities must cancel to end the move on the joint.
  Vec3 drift = Vec3::Zero();
  if (t.h > 0) {
    drift = anchor_move(b, anchors.rb, t.h) - anchor_move(*j.a, anchors.ra, t.h) -
            t.h * anchor_velocity(j, anchors);
  }
  const Vec3 impulse =
      -k.ldlt().solve(anchor_velocity(j, anchors) + drift_velocity(drift, t.h, t.most_speed));
  row.joint.linear_impulse += impulse;
  apply_linear(j, anchors.ra, anchors.rb, impulse);
  return (k * impulse).lpNorm<Eigen::Infinity>();
}

// A hinge's two angular rows: axis a stays perpendicular to two directions b2, c2 perpendicular
// to axis b (Jolt's HingeRotationConstraintPart has the same rows). d/dt (axis_a . d) =
// (w_b - w_a) . (d x axis_a) for d fixed in b, so the rows' directions are g = d x axis_a.
struct HingeRows {
  Vec3 axis_a, b2, c2, g1, g2;
  Eigen::Matrix2d k;  // effective inverse mass of the two rows
  Eigen::Vector2d error() const { return {axis_a.dot(b2), axis_a.dot(c2)}; }
};

HingeRows hinge_rows(const Joint& joint, const Quat& qa, const Quat* qb, const Mat3& inertia) {
  HingeRows rows;
  rows.axis_a = qa * joint.axis_a;
  const Vec3 axis_b = qb == nullptr ? joint.axis_b : Vec3(*qb * joint.axis_b);
  rows.b2 = perpendicular(axis_b);
  rows.c2 = axis_b.cross(rows.b2);
  rows.g1 = rows.b2.cross(rows.axis_a);
  rows.g2 = rows.c2.cross(rows.axis_a);
  rows.k(0, 0) = rows.g1.dot(inertia * rows.g1);
  rows.k(0, 1) = rows.k(1, 0) = rows.g1.dot(inertia * rows.g2);
  rows.k(1, 1) = rows.g2.dot(inertia * rows.g2);
  return rows;
}

double solve_hinge_axes(JointRow& row, JointBodies& j, const JointTarget& t) {
  const SolverBody& b = j.body_b();
  const HingeRows rows =
      hinge_rows(row.joint, j.pose_a.orientation, j.b == nullptr ? nullptr : &j.pose_b.orientation,
                 j.a->inverse_inertia + b.inverse_inertia);
  const Vec3 &axis_a = rows.axis_a, &b2 = rows.b2, &c2 = rows.c2, &g1 = rows.g1, &g2 = rows.g2;
  const Eigen::Matrix2d& k = rows.k;
  const Vec3 relative_w = b.w - j.a->w;
  if (!(k.determinant() > 0)) return 0;
  Eigen::Vector2d velocity(relative_w.dot(g1), relative_w.dot(g2));
  if (t.h > 0) {
    // The turns' curvature over the move, beyond the velocities' first order.
    const Quat turn_a = rotation_quaternion(t.h * j.a->w);
    const Quat turn_b = rotation_quaternion(t.h * b.w);
    const Vec3 a_next = turn_a * axis_a, b2_next = turn_b * b2, c2_next = turn_b * c2;
    const Vec3 drift(a_next.dot(b2_next) - axis_a.dot(b2) - t.h * velocity.x(),
                     a_next.dot(c2_next) - axis_a.dot(c2) - t.h * velocity.y(), 0);
    const Vec3 extra = drift_velocity(drift, t.h, t.most_speed);
    velocity += Eigen::Vector2d(extra.x(), extra.y());
  }
  const Eigen::Vector2d lambda = -k.ldlt().solve(velocity);
  const Vec3 angular = lambda.x() * g1 + lambda.y() * g2;
  row.joint.angular_impulse += angular;
  apply_angular(j, angular);
  return (k * lambda).lpNorm<Eigen::Infinity>();
}

// A fixed joint's rotation: three rows, the rotation of b from where a's rotation says it should
// be, as a rotation vector.
Vec3 rotation_error(const Joint& joint, const Quat& qa, const Quat& qb) {
  Quat error = qb * (qa * joint.relative).conjugate();
  if (error.w() < 0) error.coeffs() = -error.coeffs();
  return 2 * error.vec();
}

// (The relative turn's curvature over a move is third order: nothing to add for a move ahead.)
double solve_fixed_rotation(JointRow& row, JointBodies& j) {
  const SolverBody& b = j.body_b();
  const Mat3 k = j.a->inverse_inertia + b.inverse_inertia;
  if (!(k.determinant() > 0)) return 0;
  const Vec3 impulse = -k.ldlt().solve(Vec3(b.w - j.a->w));
  row.joint.angular_impulse += impulse;
  apply_angular(j, impulse);
  return (k * impulse).lpNorm<Eigen::Infinity>();
}

// A distance joint's row along the rod.
double solve_distance(JointRow& row, JointBodies& j, const Anchors& anchors, const JointTarget& t) {
  const SolverBody& b = j.body_b();
  const Vec3 d = anchors.pb - anchors.pa;
  const double length = d.norm();
  if (!(length > 1e-12)) return 0;  // the ends meet: no direction to hold them along
  const Vec3 n = d / length;
  const Vec3 ra_n = anchors.ra.cross(n), rb_n = anchors.rb.cross(n);
  const double k = j.a->inverse_mass + b.inverse_mass + ra_n.dot(j.a->inverse_inertia * ra_n) +
                   rb_n.dot(b.inverse_inertia * rb_n);
  if (!(k > 0)) return 0;
  // With a move ahead, the rod's length after it, where the move takes the anchors: the chord,
  // not the tangent (the tangent's way, the rod stretches by v^2 h^2 / 2L a move and the next
  // sweep takes that kinetic energy away).
  const Vec3 u = anchor_velocity(j, anchors);
  double velocity = n.dot(u);
  if (t.h > 0) {
    const Vec3 d_next = d + anchor_move(b, anchors.rb, t.h) - anchor_move(*j.a, anchors.ra, t.h);
    velocity += drift_velocity(d_next.norm() - length - t.h * velocity, t.h, t.most_speed);
  }
  const double impulse = -velocity / k;
  row.joint.axial_impulse += impulse;
  apply_linear(j, anchors.ra, anchors.rb, impulse * n);
  return std::abs(impulse) * k;
}

}  // namespace

void warm_start_joint(const JointRow& row, std::span<SolverBody> bodies,
                      std::span<const Pose> poses) {
  JointBodies j = bodies_of(row, bodies, poses);
  const Anchors anchors = anchors_of(row.joint, j.pose_a, j.pose_b, j.b == nullptr);
  if (row.joint.kind == JointKind::kDistance) {
    const Vec3 d = anchors.pb - anchors.pa;
    const double length = d.norm();
    if (length > 1e-12)
      apply_linear(j, anchors.ra, anchors.rb, row.joint.axial_impulse / length * d);
    return;
  }
  apply_linear(j, anchors.ra, anchors.rb, row.joint.linear_impulse);
  apply_angular(j, row.joint.angular_impulse);
}

double solve_joint(JointRow& row, std::span<SolverBody> bodies, std::span<const Pose> poses,
                   const JointTarget& target) {
  JointBodies j = bodies_of(row, bodies, poses);
  // The rotation first, then the point, whose lever arms the rotation changed last (Box2D v3's
  // revolute joint's order).
  double change = 0;
  switch (row.joint.kind) {
    case JointKind::kHinge:
      change = solve_hinge_axes(row, j, target);
      break;
    case JointKind::kFixed:
      change = solve_fixed_rotation(row, j);
      break;
    case JointKind::kBall:
    case JointKind::kDistance:
      break;
  }
  const Anchors anchors = anchors_of(row.joint, j.pose_a, j.pose_b, j.b == nullptr);
  if (row.joint.kind == JointKind::kDistance)
    return std::max(change, solve_distance(row, j, anchors, target));
  return std::max(change, solve_point(row, j, anchors, target));
}

namespace {

// A body moved by a correction: its pose, and its motion since the step start, which the
// contacts' separations are measured from (current_separation). Statics and the world stay.
void move_body(SolverBody* body, Pose* pose, const Vec3& dx, const Vec3& dtheta) {
  if (body == nullptr || body->inverse_mass == 0) return;
  pose->position += dx;
  pose->orientation = rotated(pose->orientation, dtheta);
  body->delta_position += dx;
  body->delta_angle += dtheta;
}

struct MovingBodies {
  SolverBody* a;
  SolverBody* b;  // null: the world
  Pose* pose_a;
  Pose* pose_b;  // null: the world
  const SolverBody& body_b() const { return b != nullptr ? *b : kWorldBody; }
  Pose world_pose_b() const { return pose_b != nullptr ? *pose_b : Pose{}; }
};

// Displacement p at the anchors (on b; a takes -p) through the bodies' inverse masses.
void displace_linear(MovingBodies& m, const Vec3& ra, const Vec3& rb, const Vec3& p) {
  move_body(m.a, m.pose_a, -m.a->inverse_mass * p, -(m.a->inverse_inertia * ra.cross(p)));
  if (m.b != nullptr)
    move_body(m.b, m.pose_b, m.b->inverse_mass * p, m.b->inverse_inertia * rb.cross(p));
}

void displace_angular(MovingBodies& m, const Vec3& l) {
  move_body(m.a, m.pose_a, Vec3::Zero(), -(m.a->inverse_inertia * l));
  if (m.b != nullptr) move_body(m.b, m.pose_b, Vec3::Zero(), m.b->inverse_inertia * l);
}

}  // namespace

void correct_joint_position(const JointRow& row, std::span<SolverBody> bodies,
                            std::span<Pose> poses) {
  const bool world_b = row.b == kWorldAnchor;
  MovingBodies m{&bodies[row.a], world_b ? nullptr : &bodies[row.b], &poses[row.a],
                 world_b ? nullptr : &poses[row.b]};
  const Joint& joint = row.joint;
  const SolverBody& b = m.body_b();
  // The rotation first (it moves the anchors), then the point or the length.
  if (joint.kind == JointKind::kHinge) {
    const HingeRows rows =
        hinge_rows(joint, m.pose_a->orientation, world_b ? nullptr : &m.pose_b->orientation,
                   m.a->inverse_inertia + b.inverse_inertia);
    if (rows.k.determinant() > 0) {
      const Eigen::Vector2d lambda = -rows.k.ldlt().solve(rows.error());
      displace_angular(m, lambda.x() * rows.g1 + lambda.y() * rows.g2);
    }
  } else if (joint.kind == JointKind::kFixed) {
    const Mat3 k = m.a->inverse_inertia + b.inverse_inertia;
    const Quat qb = world_b ? Quat::Identity() : m.pose_b->orientation;
    const Vec3 error = rotation_error(joint, m.pose_a->orientation, qb);
    if (k.determinant() > 0) displace_angular(m, -k.ldlt().solve(error));
  }
  const Anchors anchors = anchors_of(joint, *m.pose_a, m.world_pose_b(), world_b);
  const Vec3 d = anchors.pb - anchors.pa;
  if (joint.kind == JointKind::kDistance) {
    const double length = d.norm();
    if (!(length > 1e-12)) return;
    const Vec3 n = d / length;
    const Vec3 ra_n = anchors.ra.cross(n), rb_n = anchors.rb.cross(n);
    const double k = m.a->inverse_mass + b.inverse_mass + ra_n.dot(m.a->inverse_inertia * ra_n) +
                     rb_n.dot(b.inverse_inertia * rb_n);
    if (k > 0) displace_linear(m, anchors.ra, anchors.rb, -(length - joint.length) / k * n);
    return;
  }
  const Mat3 ra_skew = skew(anchors.ra), rb_skew = skew(anchors.rb);
  const Mat3 k = (m.a->inverse_mass + b.inverse_mass) * Mat3::Identity() -
                 ra_skew * m.a->inverse_inertia * ra_skew - rb_skew * b.inverse_inertia * rb_skew;
  displace_linear(m, anchors.ra, anchors.rb, -k.ldlt().solve(d));
}

double joint_error(const Joint& joint, const Pose& pose_a, const Pose& pose_b) {
  const bool world_b = joint.b == kWorldAnchor;
  const Anchors anchors = anchors_of(joint, pose_a, pose_b, world_b);
  const Vec3 d = anchors.pb - anchors.pa;
  switch (joint.kind) {
    case JointKind::kBall:
      return d.norm();
    case JointKind::kDistance:
      return std::abs(d.norm() - joint.length);
    case JointKind::kHinge: {
      const Vec3 axis_a = pose_a.orientation * joint.axis_a;
      const Vec3 axis_b = world_b ? joint.axis_b : Vec3(pose_b.orientation * joint.axis_b);
      return std::max(d.norm(), axis_a.cross(axis_b).norm());
    }
    case JointKind::kFixed: {
      const Quat qb = world_b ? Quat::Identity() : pose_b.orientation;
      return std::max(d.norm(), rotation_error(joint, pose_a.orientation, qb).norm());
    }
  }
  return 0;
}

}  // namespace tumble
