#include "joint_solver.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <type_traits>

#include "joint_axial.h"
#include "joint_geometry.h"
#include "joint_terms.h"
#include "rotation.h"

namespace tumble {
namespace {

using namespace joint_detail;

// How far an anchor r (from the centre of mass) moves over a move of h: the body's translation
// and its exact turn, as the move makes them.
Vec3 anchor_move(const SolverBody& body, const Vec3& r, double h) {
  const Vec3 theta = h * body.w;
  return h * body.v + (theta.cross(r) + turn_curvature(theta, r));
}
// The same with the body's turn over the move, rotation_quaternion(h w), known.
Vec3 anchor_move(const SolverBody& body, const Quat& turn, const Vec3& r, double h) {
  return h * body.v + (turn * r - r);
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

// The point constraint of ball, hinge and fixed joints: three rows solved together; their block.
Mat3 point_block(const SolverBody& a, const SolverBody& b, const Anchors& anchors) {
  Mat3 block = (a.inverse_mass + b.inverse_mass) * Mat3::Identity();
  add_lever_inertia(a.inverse_inertia, anchors.ra, &block);
  add_lever_inertia(b.inverse_inertia, anchors.rb, &block);
  return block;
}

double solve_point(JointRow& row, JointBodies& j, const JointPoseTerms& terms,
                   const JointTarget& t) {
  const SolverBody& b = j.body_b();
  const Anchors& anchors = terms.anchors;
  const Mat3& k = terms.point;
  // The move's drift beyond the velocities' first order (the turns' curvature), which the
  // velocities must cancel to end the move on the joint.
  Vec3 drift = Vec3::Zero();
  if (t.h > 0 && t.curvature)
    drift = turn_curvature(t.h * b.w, anchors.rb) - turn_curvature(t.h * j.a->w, anchors.ra);
  const Vec3 impulse = -terms.point_solver.solve(anchor_velocity(j, anchors) +
                                                 drift_velocity(drift, t.h, t.most_speed));
  row.joint.linear_impulse += impulse;
  apply_linear(j, anchors.ra, anchors.rb, impulse);
  return (k * impulse).lpNorm<Eigen::Infinity>();
}

}  // namespace

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

namespace {

double solve_hinge_axes(JointRow& row, JointBodies& j, const JointTarget& t,
                        const JointPoseTerms& terms) {
  const SolverBody& b = j.body_b();
  const HingeRows& rows = terms.hinge;
  const Vec3 &axis_a = rows.axis_a, &b2 = rows.b2, &c2 = rows.c2, &g1 = rows.g1, &g2 = rows.g2;
  const Eigen::Matrix2d& k = rows.k;
  const Vec3 relative_w = b.w - j.a->w;
  if (!terms.hinge_usable) return 0;
  Eigen::Vector2d velocity(relative_w.dot(g1), relative_w.dot(g2));
  if (t.h > 0 && t.curvature) {
    // The turns' curvature over the move, beyond the velocities' first order.
    const Vec3 turn_a = t.h * j.a->w, turn_b = t.h * b.w;
    const auto turned = [](const Vec3& theta, const Vec3& r) {
      return Vec3(r + theta.cross(r) + turn_curvature(theta, r));
    };
    const Vec3 a_next = turned(turn_a, axis_a), b2_next = turned(turn_b, b2),
               c2_next = turned(turn_b, c2);
    const Vec3 drift(a_next.dot(b2_next) - axis_a.dot(b2) - t.h * velocity.x(),
                     a_next.dot(c2_next) - axis_a.dot(c2) - t.h * velocity.y(), 0);
    const Vec3 extra = drift_velocity(drift, t.h, t.most_speed);
    velocity += Eigen::Vector2d(extra.x(), extra.y());
  }
  const Eigen::Vector2d lambda = -terms.hinge_solver.solve(velocity);
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
double solve_fixed_rotation(JointRow& row, JointBodies& j, const JointPoseTerms& terms) {
  const SolverBody& b = j.body_b();
  const Mat3& k = terms.rotation;
  if (!terms.rotation_usable) return 0;
  const Vec3 impulse = -terms.rotation_solver.solve(Vec3(b.w - j.a->w));
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
  if (t.h > 0 && t.curvature) {
    const Vec3 d_next = d + anchor_move(b, anchors.rb, t.h) - anchor_move(*j.a, anchors.ra, t.h);
    velocity += drift_velocity(d_next.norm() - length - t.h * velocity, t.h, t.most_speed);
  }
  const double impulse = -velocity / k;
  row.joint.axial_impulse += impulse;
  apply_linear(j, anchors.ra, anchors.rb, impulse * n);
  return std::abs(impulse) * k;
}

}  // namespace

SliderRows slider_rows(const Joint& joint, const Pose& pose_a, const Pose& pose_b, bool world_b,
                       const SolverBody& a, const SolverBody& b) {
  SliderRows s;
  const Anchors anchors = anchors_of(joint, pose_a, pose_b, world_b);
  const Vec3 axis = pose_a.orientation * joint.axis_a;
  const Vec3 d = anchors.pb - anchors.pa;
  const Vec3 t1 = perpendicular(axis), t2 = axis.cross(t1);
  const Vec3 across[2] = {t1, t2};
  for (int i = 0; i < 2; ++i) {
    s.rows[i] = {across[i], -(anchors.ra + d).cross(across[i]), anchors.rb.cross(across[i])};
    s.error[i] = d.dot(across[i]);
  }
  for (int i = 0; i < 2; ++i)
    for (int k = 0; k < 2; ++k)
      s.k(i, k) = (a.inverse_mass + b.inverse_mass) * across[i].dot(across[k]) +
                  s.rows[i].angular_a.dot(a.inverse_inertia * s.rows[k].angular_a) +
                  s.rows[i].angular_b.dot(b.inverse_inertia * s.rows[k].angular_b);
  return s;
}

namespace {

double solve_slider_across(JointRow& row, JointBodies& j, const JointPoseTerms& terms) {
  const SliderRows& s = terms.slider;
  if (!terms.slider_usable) return 0;
  const Eigen::Vector2d rate(row_rate(s.rows[0], *j.a, j.body_b()),
                             row_rate(s.rows[1], *j.a, j.body_b()));
  const Eigen::Vector2d lambda = -terms.slider_solver.solve(rate);
  for (int i = 0; i < 2; ++i)
    apply_row(j, s.rows[i], lambda[i]);
  row.joint.linear_impulse += lambda[0] * s.rows[0].linear + lambda[1] * s.rows[1].linear;
  return (s.k * lambda).lpNorm<Eigen::Infinity>();
}

}  // namespace

void prepare_joint_terms(const JointRow& row, std::span<const SolverBody> bodies,
                         std::span<const Pose> poses, bool own_rows, JointPoseTerms* terms) {
  const Joint& joint = row.joint;
  const bool world_b = row.b == kWorldAnchor;
  const SolverBody& a = bodies[row.a];
  const SolverBody& body_b = world_b ? kWorldBody : bodies[row.b];
  const Pose& pose_a = poses[row.a];
  const Pose pose_b = world_b ? Pose{} : poses[row.b];
  terms->anchors = anchors_of(joint, pose_a, pose_b, world_b);
  prepare_axial_terms(joint, a, body_b, pose_a, pose_b, world_b, terms);
  if (!own_rows) return;
  switch (joint.kind) {
    case JointKind::kHinge:
      terms->hinge = hinge_rows(joint, pose_a.orientation, world_b ? nullptr : &pose_b.orientation,
                                a.inverse_inertia + body_b.inverse_inertia);
      terms->hinge_usable = terms->hinge.k.determinant() > 0;
      if (terms->hinge_usable) terms->hinge_solver.compute(terms->hinge.k);
      break;
    case JointKind::kFixed:
    case JointKind::kSlider:
      terms->rotation = a.inverse_inertia + body_b.inverse_inertia;
      terms->rotation_usable = terms->rotation.determinant() > 0;
      if (terms->rotation_usable) terms->rotation_solver.compute(terms->rotation);
      break;
    case JointKind::kBall:
    case JointKind::kDistance:
      break;
  }
  if (joint.kind == JointKind::kSlider) {
    terms->slider = slider_rows(joint, pose_a, pose_b, world_b, a, body_b);
    terms->slider_usable = terms->slider.k.determinant() > 0;
    if (terms->slider_usable) terms->slider_solver.compute(terms->slider.k);
  } else if (joint.kind != JointKind::kDistance) {
    terms->point = point_block(a, body_b, terms->anchors);
    terms->point_solver.compute(terms->point);
  }
}

void warm_start_joint(const JointRow& row, std::span<SolverBody> bodies,
                      std::span<const Pose> poses, const JointPoseTerms& terms) {
  JointBodies j = bodies_of(row, bodies, poses);
  warm_start_axial(row, j, terms);
  const Anchors& anchors = terms.anchors;
  switch (row.joint.kind) {
    case JointKind::kDistance: {
      const Vec3 d = anchors.pb - anchors.pa;
      const double length = d.norm();
      if (length > 1e-12 && rigid_distance(row.joint))
        apply_linear(j, anchors.ra, anchors.rb, row.joint.axial_impulse / length * d);
      return;
    }
    case JointKind::kSlider:
      // The rows across the axis reach b's anchor from a's centre.
      apply_linear(j, anchors.pb - j.pose_a.position, anchors.rb, row.joint.linear_impulse);
      break;
    default:
      apply_linear(j, anchors.ra, anchors.rb, row.joint.linear_impulse);
  }
  apply_angular(j, row.joint.angular_impulse);
}

double solve_joint(JointRow& row, std::span<SolverBody> bodies, std::span<const Pose> poses,
                   const JointTarget& target, const JointPoseTerms& terms) {
  JointBodies j = bodies_of(row, bodies, poses);
  // Springs, motors and limits first, so that the rows that must hold have the last word; then
  // the rotation, then the point, whose lever arms the rotation changed last (Box2D v3's
  // revolute joint's order).
  double change = solve_axial(row, j, target, terms);
  switch (row.joint.kind) {
    case JointKind::kHinge:
      change = std::max(change, solve_hinge_axes(row, j, target, terms));
      break;
    case JointKind::kFixed:
    case JointKind::kSlider:
      change = std::max(change, solve_fixed_rotation(row, j, terms));
      break;
    case JointKind::kBall:
    case JointKind::kDistance:
      break;
  }
  if (row.joint.kind == JointKind::kSlider)
    return std::max(change, solve_slider_across(row, j, terms));
  if (row.joint.kind == JointKind::kDistance)
    return rigid_distance(row.joint)
               ? std::max(change, solve_distance(row, j, terms.anchors, target))
               : change;
  return std::max(change, solve_point(row, j, terms, target));
}

namespace {

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
  // The bounds first, then the rotation (it moves the anchors), then the point or the length.
  correct_axial(joint, m.a, m.b, m.pose_a, m.pose_b);
  if (joint.kind == JointKind::kHinge) {
    const HingeRows rows =
        hinge_rows(joint, m.pose_a->orientation, world_b ? nullptr : &m.pose_b->orientation,
                   m.a->inverse_inertia + b.inverse_inertia);
    if (rows.k.determinant() > 0) {
      const Eigen::Vector2d lambda = -solve_block<2>(rows.k, rows.error());
      displace_angular(m, lambda.x() * rows.g1 + lambda.y() * rows.g2);
    }
  } else if (joint.kind == JointKind::kFixed || joint.kind == JointKind::kSlider) {
    const Mat3 k = m.a->inverse_inertia + b.inverse_inertia;
    const Quat qb = world_b ? Quat::Identity() : m.pose_b->orientation;
    const Vec3 error = rotation_error(joint, m.pose_a->orientation, qb);
    if (k.determinant() > 0) displace_angular(m, -solve_block<3>(k, error));
  }
  if (joint.kind == JointKind::kSlider) {
    const SliderRows s = slider_rows(joint, *m.pose_a, m.world_pose_b(), world_b, *m.a, b);
    if (!(s.k.determinant() > 0)) return;
    const Eigen::Vector2d lambda = -solve_block<2>(s.k, s.error);
    for (int i = 0; i < 2; ++i)
      displace_row(s.rows[i], lambda[i], m.a, m.b, m.pose_a, m.pose_b);
    return;
  }
  const Anchors anchors = anchors_of(joint, *m.pose_a, m.world_pose_b(), world_b);
  const Vec3 d = anchors.pb - anchors.pa;
  if (joint.kind == JointKind::kDistance) {
    const double length = d.norm();
    if (!(length > 1e-12) || !rigid_distance(joint)) return;
    const Vec3 n = d / length;
    const Vec3 ra_n = anchors.ra.cross(n), rb_n = anchors.rb.cross(n);
    const double k = m.a->inverse_mass + b.inverse_mass + ra_n.dot(m.a->inverse_inertia * ra_n) +
                     rb_n.dot(b.inverse_inertia * rb_n);
    if (k > 0) displace_linear(m, anchors.ra, anchors.rb, -(length - joint.length) / k * n);
    return;
  }
  displace_linear(m, anchors.ra, anchors.rb, -solve_block<3>(point_block(*m.a, b, anchors), d));
}

JointReading read_joint(const Joint& joint, const Pose& pose_a, const Pose& pose_b,
                        const SolverBody& a, const SolverBody& b) {
  const bool world_b = joint.b == kWorldAnchor;
  JointReading reading = read_axial(joint, pose_a, pose_b, a, b, world_b);
  if (!(joint.impulse_time > 0)) return reading;
  // The free coordinate's rows' share: along the row, as force (sliders, distance) or torque.
  const FreeCoordinate c = free_coordinate(joint, pose_a, pose_b, world_b);
  Vec3 linear = joint.linear_impulse, angular = joint.angular_impulse;
  if (c.exists) {
    const double along = impulse_along(joint);
    linear += along * c.row.linear;
    if (c.row.linear.isZero()) angular += along * c.row.angular_b;
  }
  if (joint.swing_impulse != 0) {
    const Swing swing = swing_of(joint, pose_a.orientation, pose_b.orientation);
    if (swing.exists) angular -= joint.swing_impulse * swing.row.angular_b;
  }
  if (joint.kind == JointKind::kBall) angular += joint.friction_impulse;  // its turn's friction
  reading.force = linear / joint.impulse_time;
  reading.torque = angular / joint.impulse_time;
  return reading;
}

double joint_error(const Joint& joint, const Pose& pose_a, const Pose& pose_b) {
  const bool world_b = joint.b == kWorldAnchor;
  const Quat qb = world_b ? Quat::Identity() : pose_b.orientation;
  const Anchors anchors = anchors_of(joint, pose_a, pose_b, world_b);
  const Vec3 d = anchors.pb - anchors.pa;
  // (A bound the poses are clearly within adds nothing: no exact angle; rough_atan2.h.)
  double bounds = 0;
  if (joint.limit.enabled && !clearly_within_limit(joint, pose_a.orientation, qb, 0)) {
    const FreeCoordinate c = free_coordinate(joint, pose_a, pose_b, world_b);
    if (c.exists) bounds = limit_violation(joint, c.position);
  }
  if (joint.kind == JointKind::kBall && joint.max_swing < std::numbers::pi &&
      !clearly_within_cone(joint, pose_a.orientation, qb, 0)) {
    const Swing swing = swing_of(joint, pose_a.orientation, qb);
    if (swing.exists) bounds = std::max(bounds, swing.angle - joint.max_swing);
  }
  switch (joint.kind) {
    case JointKind::kBall:
      return std::max(bounds, d.norm());
    case JointKind::kDistance:
      return rigid_distance(joint) ? std::abs(d.norm() - joint.length) : bounds;
    case JointKind::kHinge: {
      const Vec3 axis_a = pose_a.orientation * joint.axis_a;
      const Vec3 axis_b = world_b ? joint.axis_b : Vec3(pose_b.orientation * joint.axis_b);
      return std::max({bounds, d.norm(), axis_a.cross(axis_b).norm()});
    }
    case JointKind::kFixed:
      return std::max(d.norm(), rotation_error(joint, pose_a.orientation, qb).norm());
    case JointKind::kSlider: {
      const Vec3 axis = pose_a.orientation * joint.axis_a;
      const Vec3 across = d - d.dot(axis) * axis;
      return std::max(
          {bounds, across.norm(), rotation_error(joint, pose_a.orientation, qb).norm()});
    }
  }
  return 0;
}

namespace {

using Row6 = Eigen::Matrix<double, 1, 6>;

// A row whose rate is linear . (v_b - v_a) + angular_a . w_a + angular_b . w_b.
void set_row(JointEquations& e, int i, const AxialRow& row) {
  if (i < 3) e.point_linear_held = false;
  e.on_a.row(i) << -row.linear.transpose(), row.angular_a.transpose();
  e.on_b.row(i) << row.linear.transpose(), row.angular_b.transpose();
}

// [v]x (or minus it) into columns 3-5 of three rows, each entry written where it goes: built as
// a Mat3 and copied, its columns were loaded back from the stack before their stores had landed
// (a stall a column, 4% of chain:100's step). The same values, and the same signed zeros.
template <bool Negated>
void set_cross_block(Eigen::Matrix<double, 6, 6>& rows, int first, const Vec3& v) {
  const auto put = [&](int i, int j, double x) { rows(first + i, 3 + j) = Negated ? -x : x; };
  put(0, 0, 0.0);
  put(1, 0, v.z());
  put(2, 0, -v.y());
  put(0, 1, -v.z());
  put(1, 1, 0.0);
  put(2, 1, v.x());
  put(0, 2, v.y());
  put(1, 2, -v.x());
  put(2, 2, 0.0);
}

// Three rows at once: the point (rate: b's anchor's velocity less a's), or the rotation
// (w_b - w_a).
void set_point_rows(JointEquations& e, int first, const Anchors& anchors) {
  e.point_rows = first == 0;
  if (first != 0 || !e.point_linear_held) {
    e.on_a.block<3, 3>(first, 0) = -Mat3::Identity();
    e.on_b.block<3, 3>(first, 0) = Mat3::Identity();
    if (first < 3) e.point_linear_held = first == 0;
  }
  set_cross_block<false>(e.on_a, first, anchors.ra);
  set_cross_block<true>(e.on_b, first, anchors.rb);
}
void set_rotation_rows(JointEquations& e, int first) {
  if (first < 3) e.point_linear_held = false;
  e.on_a.block<3, 3>(first, 0).setZero();
  e.on_a.block<3, 3>(first, 3) = -Mat3::Identity();
  e.on_b.block<3, 3>(first, 0).setZero();
  e.on_b.block<3, 3>(first, 3) = Mat3::Identity();
}

// Every writer above writes whole rows, so of the rows past the new count only those the last
// equations held need clearing (JointEquations keeps them zero): clearing both 6 x 6 matrices
// outright was a fifth of a chain's position equations (7.1 M of 33.1 M instructions, callgrind).
int start_equations(JointEquations* e) {
  const int held = e->rows;
  e->rows = 0;
  e->point_rows = false;
  e->turning_rest = false;
  e->target.setZero();
  return held;
}
void finish_equations(JointEquations* e, int held) {
  if (e->rows < std::min(held, 3)) e->point_linear_held = false;
  for (int i = e->rows; i < held; ++i) {
    e->on_a.row(i).setZero();
    e->on_b.row(i).setZero();
  }
}

// What equations_of fills without the rows: their count and targets.
struct JointTargets {
  int rows = 0;
  JointEquations::Vector target = JointEquations::Vector::Zero();
};

// Both: the rows at the present poses (into a JointEquations between start_equations and
// finish_equations, each row written whole; else the targets alone); `velocities` asks for the
// targets of a sweep (else the targets are minus the errors), with each body's turn over the move
// (rotation_quaternion(h w)) in `turns` by solver index where given.
template <class Out>
void equations_of(Out& e, const JointRow& row, std::span<const SolverBody> bodies,
                  std::span<const Pose> poses, const JointTarget* velocities,
                  const Quat* turns = nullptr, const Anchors* known_anchors = nullptr) {
  constexpr bool kRows = std::is_same_v<Out, JointEquations>;
  JointEquations::Vector& target = e.target;
  const Joint& joint = row.joint;
  const bool world_b = row.b == kWorldAnchor;
  const SolverBody& a = bodies[row.a];
  const SolverBody& b = world_b ? kWorldBody : bodies[row.b];
  const Pose& pose_a = poses[row.a];
  const Pose pose_b = world_b ? Pose{} : poses[row.b];
  const Anchors anchors =
      known_anchors != nullptr ? *known_anchors : anchors_of(joint, pose_a, pose_b, world_b);
  const double h = velocities != nullptr ? velocities->h : 0;
  const double most = velocities != nullptr ? velocities->most_speed : 0;
  // (b.v + b.w x rb) - (a.v + a.w x ra), a coordinate at a time in Eigen's own order: the cross
  // products built in memory one value at a time and added two at a time stalled on store
  // forwarding (a fifth of this function's time). The same bits.
  const auto point_velocity = [](const SolverBody& body, const Vec3& r, int i) {
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    return body.v[i] + (body.w[j] * r[k] - body.w[k] * r[j]);
  };
  const Vec3 rate(point_velocity(b, anchors.rb, 0) - point_velocity(a, anchors.ra, 0),
                  point_velocity(b, anchors.rb, 1) - point_velocity(a, anchors.ra, 1),
                  point_velocity(b, anchors.rb, 2) - point_velocity(a, anchors.ra, 2));
  auto turn_of_a = [&] { return turns != nullptr ? turns[row.a] : rotation_quaternion(h * a.w); };
  auto turn_of_b = [&] {
    return turns != nullptr && !world_b ? turns[row.b] : rotation_quaternion(h * b.w);
  };
  auto move_of_a = [&](const Vec3& r) {
    return turns != nullptr ? anchor_move(a, turns[row.a], r, h) : anchor_move(a, r, h);
  };
  auto move_of_b = [&](const Vec3& r) {
    return turns != nullptr && !world_b ? anchor_move(b, turns[row.b], r, h) : anchor_move(b, r, h);
  };
  auto point_target = [&] {
    if (velocities == nullptr) return Vec3(anchors.pa - anchors.pb);
    if (!(h > 0)) return Vec3(Vec3::Zero());
    const Vec3 drift = move_of_b(anchors.rb) - move_of_a(anchors.ra) - h * rate;
    return Vec3(-drift_velocity(drift, h, most));
  };
  switch (joint.kind) {
    case JointKind::kBall:
      e.rows = 3;
      if constexpr (kRows) set_point_rows(e, 0, anchors);
      target.head<3>() = point_target();
      break;
    case JointKind::kFixed: {
      e.rows = 6;
      if constexpr (kRows) set_point_rows(e, 0, anchors);
      target.head<3>() = point_target();
      if constexpr (kRows) set_rotation_rows(e, 3);
      if (velocities == nullptr)
        target.tail<3>() = -rotation_error(joint, pose_a.orientation, pose_b.orientation);
      break;
    }
    case JointKind::kHinge: {
      e.rows = 5;
      if constexpr (kRows) set_point_rows(e, 0, anchors);
      target.head<3>() = point_target();
      const HingeRows hinge = hinge_rows(joint, pose_a.orientation,
                                         world_b ? nullptr : &pose_b.orientation, Mat3::Zero());
      if constexpr (kRows) set_row(e, 3, {Vec3::Zero(), -hinge.g1, hinge.g1});
      if constexpr (kRows) set_row(e, 4, {Vec3::Zero(), -hinge.g2, hinge.g2});
      if (velocities == nullptr) {
        target.segment<2>(3) = -hinge.error();
      } else if (h > 0) {
        // The turns' curvature over the move beyond the velocities' first order.
        const Vec3 relative_w = b.w - a.w;
        const Quat turn_a = turn_of_a(), turn_b = turn_of_b();
        const Vec3 a_next = turn_a * hinge.axis_a;
        const Vec3 drift(a_next.dot(turn_b * hinge.b2) - hinge.axis_a.dot(hinge.b2) -
                             h * relative_w.dot(hinge.g1),
                         a_next.dot(turn_b * hinge.c2) - hinge.axis_a.dot(hinge.c2) -
                             h * relative_w.dot(hinge.g2),
                         0);
        target.segment<2>(3) = -drift_velocity(drift, h, most).head<2>();
      }
      break;
    }
    case JointKind::kSlider: {
      e.rows = 5;
      if constexpr (kRows) set_rotation_rows(e, 0);
      const SliderRows across = slider_rows(joint, pose_a, pose_b, world_b, a, b);
      if constexpr (kRows) set_row(e, 3, across.rows[0]);
      if constexpr (kRows) set_row(e, 4, across.rows[1]);
      if (velocities == nullptr) {
        target.head<3>() = -rotation_error(joint, pose_a.orientation, pose_b.orientation);
        target.segment<2>(3) = -across.error;
      }
      break;
    }
    case JointKind::kDistance: {
      if (!rigid_distance(joint)) break;
      const Vec3 d = anchors.pb - anchors.pa;
      const double length = d.norm();
      if (!(length > 1e-12)) break;
      const Vec3 n = d / length;
      e.rows = 1;
      if constexpr (kRows) set_row(e, 0, {n, -anchors.ra.cross(n), anchors.rb.cross(n)});
      if (velocities == nullptr) {
        target[0] = joint.length - length;
      } else if (h > 0) {
        const Vec3 d_next = d + move_of_b(anchors.rb) - move_of_a(anchors.ra);
        target[0] = -drift_velocity(d_next.norm() - length - h * n.dot(rate), h, most);
      }
      break;
    }
  }
}

}  // namespace

void velocity_equations(JointEquations* e, const JointRow& row, std::span<const SolverBody> bodies,
                        std::span<const Pose> poses, const JointTarget& target,
                        const Anchors* anchors) {
  const int held = start_equations(e);
  equations_of(*e, row, bodies, poses, &target, nullptr, anchors);
  if (row.motor_in_tree && e->rows == 5) {
    // The motor's row: the free coordinate's rate is its speed.
    const bool world_b = row.b == kWorldAnchor;
    const FreeCoordinate c =
        free_coordinate(row.joint, poses[row.a], world_b ? Pose{} : poses[row.b], world_b);
    if (c.exists) {
      set_row(*e, 5, c.row);
      e->target[5] = row.joint.motor.speed;
      e->rows = 6;
    }
  }
  finish_equations(e, held);
}

JointEquations::Vector velocity_targets(const JointRow& row, std::span<const SolverBody> bodies,
                                        std::span<const Pose> poses, const JointTarget& target,
                                        const Quat* turns, const Anchors* anchors) {
  JointTargets e;
  equations_of(e, row, bodies, poses, &target, turns, anchors);
  if (row.motor_in_tree && e.rows == 5) {
    const bool world_b = row.b == kWorldAnchor;
    if (free_coordinate(row.joint, poses[row.a], world_b ? Pose{} : poses[row.b], world_b).exists)
      e.target[5] = row.joint.motor.speed;
  }
  return e.target;
}

bool motor_row(const JointRow& row, const JointEquations& equations) {
  return row.motor_in_tree && equations.rows == 6 &&
         (row.joint.kind == JointKind::kHinge || row.joint.kind == JointKind::kSlider);
}

namespace {

// The joint's bounds as rows after its own, targets minus how far the poses are past them: the
// ones past now (and a locked limit) where `choose`, setting *which; else those in *which, past
// or not (the rows of the factoring their targets are solved with).
template <class Out>
void append_bound_rows(Out& e, const JointRow& row, std::span<const Pose> poses, bool choose,
                       std::uint8_t* which, double slack = 0) {
  const Joint& joint = row.joint;
  const bool world_b = row.b == kWorldAnchor;
  const Pose& pose_a = poses[row.a];
  const Pose pose_b = world_b ? Pose{} : poses[row.b];
  const auto add = [&](const AxialRow& axial, double past) {
    const int i = e.rows++;
    if constexpr (std::is_same_v<Out, JointEquations>) {
      if (i < 3) e.point_linear_held = false;
      e.on_a.template block<1, 3>(i, 0) = -axial.linear.transpose();
      e.on_a.template block<1, 3>(i, 3) = axial.angular_a.transpose();
      e.on_b.template block<1, 3>(i, 0) = axial.linear.transpose();
      e.on_b.template block<1, 3>(i, 3) = axial.angular_b.transpose();
    }
    e.target[i] = -past;
  };
  if (choose) *which = 0;
  // Choosing, a bound the poses are clearly short of (rough_atan2.h) is not past it: no exact
  // angle, no row.
  if (has_cone(joint) && (choose || (*which & kConeRow)) &&
      !(choose && clearly_within_cone(joint, pose_a.orientation, pose_b.orientation, slack))) {
    const Swing swing = swing_of(joint, pose_a.orientation, pose_b.orientation);
    const double over = swing.exists ? swing.angle - joint.max_swing : 0.0;
    if (!choose || (swing.exists && over > slack && e.rows < 6)) {
      add(swing.row, over);
      if (choose) *which |= kConeRow;
    }
  }
  if (joint.limit.enabled && (choose || (*which & kLimitRow)) &&
      !(choose && clearly_within_limit(joint, pose_a.orientation, pose_b.orientation, slack))) {
    const FreeCoordinate c = free_coordinate(joint, pose_a, pose_b, world_b);
    const bool locked = joint.limit.lower == joint.limit.upper;
    double past = 0;  // signed as the coordinate
    if (c.exists && (c.position < joint.limit.lower || locked))
      past = c.position - joint.limit.lower;
    else if (c.exists && c.position > joint.limit.upper)
      past = c.position - joint.limit.upper;
    const bool chosen = slack > 0 ? std::abs(past) > slack : past != 0 || locked;
    if (!choose || (c.exists && chosen && e.rows < 6)) {
      add(c.row, past);
      if (choose) *which |= kLimitRow;
    }
  }
}

}  // namespace

void position_equations(JointEquations* e, const JointRow& row, std::span<const SolverBody> bodies,
                        std::span<const Pose> poses, std::uint8_t* bounds, double bound_slack) {
  const int held = start_equations(e);
  equations_of(*e, row, bodies, poses, nullptr);
  if (bounds != nullptr) append_bound_rows(*e, row, poses, true, bounds, bound_slack);
  finish_equations(e, held);
}

JointEquations::Vector position_targets(const JointRow& row, std::span<const SolverBody> bodies,
                                        std::span<const Pose> poses, std::uint8_t bounds) {
  JointTargets e;
  equations_of(e, row, bodies, poses, nullptr);
  if (bounds != 0) append_bound_rows(e, row, poses, false, &bounds);
  return e.target;
}

void add_equation_impulses(JointRow& row, const JointEquations& equations,
                           const Eigen::Matrix<double, 6, 1>& impulses) {
  Joint& joint = row.joint;
  if (joint.kind == JointKind::kDistance) {
    if (equations.rows == 1) joint.axial_impulse += impulses[0];
    return;
  }
  // A row that pushes a's centre is a force at the anchors; one that only turns is a torque.
  int rows = equations.rows;
  if (motor_row(row, equations)) joint.motor_impulse += impulses[--rows];
  int i = 0;
  if (equations.point_rows) {
    // A point's rows push along the world axes (on a: -I).
    joint.linear_impulse += impulses.head<3>();
    i = 3;
  }
  for (; i < rows; ++i) {
    const Vec3 linear = -equations.on_a.block<1, 3>(i, 0).transpose();
    if (!linear.isZero())
      joint.linear_impulse += impulses[i] * linear;
    else
      joint.angular_impulse += impulses[i] * -equations.on_a.block<1, 3>(i, 3).transpose();
  }
}

double solve_joint_drives(JointRow& row, std::span<SolverBody> bodies, std::span<const Pose> poses,
                          const JointTarget& target, const JointPoseTerms& terms, bool bounds) {
  JointBodies j = bodies_of(row, bodies, poses);
  return solve_axial(row, j, target, terms, bounds);
}

}  // namespace tumble
