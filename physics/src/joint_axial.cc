#include "joint_axial.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace tumble {
namespace {

using namespace joint_detail;

constexpr double kPi = std::numbers::pi;

// An angle's difference taken the short way round, in (-pi, pi].
double wrapped(double angle) {
  angle = std::remainder(angle, 2 * kPi);
  return angle == -kPi ? kPi : angle;
}

bool is_angle(JointKind kind) {
  return kind == JointKind::kHinge || kind == JointKind::kBall;
}

// The spring's stretch: the coordinate's distance from where the spring rests.
double stretch(const Joint& joint, double position) {
  if (joint.kind == JointKind::kDistance) return position - joint.length;
  const double d = position - joint.spring.target;
  return is_angle(joint.kind) ? wrapped(d) : d;
}

AxialRow negated(const AxialRow& row) {
  return {-row.linear, -row.angular_a, -row.angular_b};
}

// A one-sided row: gap >= 0 is what must hold (its rate is the row's), the impulse accumulated in
// *impulse stays >= 0. The gap may close over the coming move (the speculative margin), no more.
double solve_bound(JointBodies& j, const AxialRow& row, double mass, double gap, double h,
                   double* impulse) {
  const double rate = row_rate(row, *j.a, j.body_b());
  const double step = -(rate + std::max(gap, 0.0) / h) / mass;
  const double total = std::max(*impulse + step, 0.0);
  const double applied = total - *impulse;
  *impulse = total;
  // A bound far from its stop (most of them, most sweeps) applies nothing.
  if (applied != 0) apply_row(j, row, applied);
  return std::abs(applied) * mass;
}

// A hinge's or slider's friction: along its coordinate. A ball's: against its whole turn.
bool coordinate_friction(const Joint& joint) {
  return joint.friction > 0 && joint.kind != JointKind::kBall;
}
bool turn_friction(const Joint& joint) {
  return joint.friction > 0 && joint.kind == JointKind::kBall;
}

// A ball's friction: the angular impulse that stops b's turn relative to a, its accumulated
// whole held within the friction torque times the substep (the disc of Coulomb's law about
// every axis at once, as a contact's friction holds its tangent impulse).
double solve_turn_friction(JointBodies& j, Joint& joint, double h, const JointPoseTerms& terms) {
  if (!terms.mobility_usable) return 0;
  const Vec3 wanted = joint.friction_impulse - terms.mobility_solver.solve(j.body_b().w - j.a->w);
  if (!wanted.allFinite()) return 0;
  const double most = joint.friction * h;
  const double size = wanted.norm();
  const Vec3 total = size > most ? Vec3(wanted * (most / size)) : wanted;
  const Vec3 applied = total - joint.friction_impulse;
  joint.friction_impulse = total;
  apply_angular(j, applied);
  return (terms.mobility * applied).lpNorm<Eigen::Infinity>();
}

// What solve_axial works along the free coordinate for.
bool has_drives(const Joint& joint) {
  return joint.spring.enabled || joint.motor.enabled || joint.limit.enabled ||
         coordinate_friction(joint);
}

}  // namespace

double impulse_along(const Joint& joint) {
  if (rigid_distance(joint)) return joint.axial_impulse;
  return joint.limit_impulse + joint.motor_impulse + joint.spring_impulse +
         (coordinate_friction(joint) ? joint.friction_impulse.x() : 0.0);
}

void prepare_axial_terms(const Joint& joint, const SolverBody& a, const SolverBody& b,
                         const Pose& pose_a, const Pose& pose_b, bool world_b,
                         JointPoseTerms* terms) {
  terms->coordinate = FreeCoordinate{};
  terms->coordinate_mass = 0;
  if (has_drives(joint) || impulse_along(joint) != 0) {
    terms->coordinate = free_coordinate(joint, pose_a, pose_b, world_b);
    if (terms->coordinate.exists) terms->coordinate_mass = row_mass(terms->coordinate.row, a, b);
  }
  terms->swing = Swing{};
  terms->cone_mass = 0;
  if (has_cone(joint)) {
    terms->swing = swing_of(joint, pose_a.orientation, pose_b.orientation);
    if (terms->swing.exists) terms->cone_mass = row_mass(terms->swing.row, a, b);
  }
  terms->mobility_usable = false;
  if (turn_friction(joint)) {
    terms->mobility.setZero();
    if (a.inverse_mass > 0) terms->mobility += a.inverse_inertia;
    if (b.inverse_mass > 0) terms->mobility += b.inverse_inertia;
    terms->mobility_solver.compute(terms->mobility);
    terms->mobility_usable = terms->mobility_solver.succeeded() && terms->mobility.trace() > 0;
  }
}

void warm_start_axial(const JointRow& row, JointBodies& j, const JointPoseTerms& terms) {
  const Joint& joint = row.joint;
  if (has_cone(joint) && joint.swing_impulse != 0 && terms.swing.exists)
    apply_row(j, negated(terms.swing.row), joint.swing_impulse);
  if (turn_friction(joint)) apply_angular(j, joint.friction_impulse);
  // A rigid rod's own impulse is warm-started with the joint's rows (joint_solver.cc).
  const double along = rigid_distance(joint) ? 0.0 : impulse_along(joint);
  if (along == 0) return;
  if (terms.coordinate.exists) apply_row(j, terms.coordinate.row, along);
}

double solve_axial(JointRow& row, JointBodies& j, const JointTarget& target,
                   const JointPoseTerms& terms, bool bounds) {
  Joint& joint = row.joint;
  const SolverBody& b = j.body_b();
  const double h = target.substep;
  double change = 0;
  const FreeCoordinate& c = terms.coordinate;
  const double mass = has_drives(joint) && c.exists ? terms.coordinate_mass : 0;
  if (mass > 0) {
    // The spring acts over the coming move, once: in the sweeps before it (a relaxation sweep's
    // visit would damp it twice over).
    if (joint.spring.enabled && target.h > 0) {
      // Implicit Euler on the spring-damper: the impulse that makes the rate at the move's end
      // what the spring and damper ask of it, the impulse itself included (gamma).
      const double softness = joint.spring.damping + h * joint.spring.stiffness;
      const double gamma = 1 / (h * softness);
      const double bias = joint.spring.stiffness * stretch(joint, c.position) / softness;
      const double rate = row_rate(c.row, *j.a, b);
      const double impulse = -(rate + bias + gamma * joint.spring_impulse) / (mass + gamma);
      joint.spring_impulse += impulse;
      apply_row(j, c.row, impulse);
      change = std::max(change, std::abs(impulse) * mass);
    }
    if (joint.motor.enabled && !row.motor_in_tree && !row.motor_at_bound) {
      const double most = joint.motor.max_force * h;
      const double rate = row_rate(c.row, *j.a, b);
      const double total =
          std::clamp(joint.motor_impulse - (rate - joint.motor.speed) / mass, -most, most);
      const double applied = total - joint.motor_impulse;
      joint.motor_impulse = total;
      apply_row(j, c.row, applied);
      change = std::max(change, std::abs(applied) * mass);
    }
    if (coordinate_friction(joint)) {
      // A zero-speed motor bounded by the friction (ODE's joint friction; Jolt's).
      const double most = joint.friction * h;
      double& held = joint.friction_impulse.x();
      const double total = std::clamp(held - row_rate(c.row, *j.a, b) / mass, -most, most);
      const double applied = total - held;
      held = total;
      apply_row(j, c.row, applied);
      change = std::max(change, std::abs(applied) * mass);
    }
    if (joint.limit.enabled) {
      if (!bounds && joint.limit.lower != joint.limit.upper) {
        // Held by the exact solver's LCP (bound_rows).
      } else if (joint.limit.lower == joint.limit.upper) {
        // Locked: an equality, its error closed by the position passes.
        const double impulse = -row_rate(c.row, *j.a, b) / mass;
        joint.limit_impulse += impulse;
        apply_row(j, c.row, impulse);
        change = std::max(change, std::abs(impulse) * mass);
      } else if (c.position - joint.limit.lower < joint.limit.upper - c.position) {
        // Nearer the lower bound: the impulse pushes the coordinate up (>= 0).
        change = std::max(change, solve_bound(j, c.row, mass, c.position - joint.limit.lower, h,
                                              &joint.limit_impulse));
      } else {
        double down = -joint.limit_impulse;
        change = std::max(
            change, solve_bound(j, negated(c.row), mass, joint.limit.upper - c.position, h, &down));
        joint.limit_impulse = -down;
      }
    }
  }
  if (turn_friction(joint)) change = std::max(change, solve_turn_friction(j, joint, h, terms));
  if (bounds && has_cone(joint)) {
    const Swing& swing = terms.swing;
    const double cone_mass = terms.cone_mass;
    if (cone_mass > 0)
      change =
          std::max(change, solve_bound(j, negated(swing.row), cone_mass,
                                       joint.max_swing - swing.angle, h, &joint.swing_impulse));
  }
  return change;
}

int bound_row_count(const Joint& joint) {
  const bool ranged_limit = joint.limit.enabled && joint.limit.lower < joint.limit.upper;
  return (ranged_limit ? 1 : 0) + (has_cone(joint) ? 1 : 0);
}

int bound_rows(const Joint& joint, const Pose& pose_a, const Pose& pose_b, bool world_b,
               BoundRow out[2]) {
  int count = 0;
  if (joint.limit.enabled && joint.limit.lower < joint.limit.upper) {
    const FreeCoordinate c = free_coordinate(joint, pose_a, pose_b, world_b);
    if (c.exists) {
      // Nearer the lower bound: the impulse pushes the coordinate up.
      if (c.position - joint.limit.lower < joint.limit.upper - c.position)
        out[count++] = {c.row, c.position - joint.limit.lower, BoundRow::Side::kLower};
      else
        out[count++] = {negated(c.row), joint.limit.upper - c.position, BoundRow::Side::kUpper};
    }
  }
  if (has_cone(joint)) {
    const Swing swing =
        swing_of(joint, pose_a.orientation, world_b ? Quat::Identity() : pose_b.orientation);
    if (swing.exists)
      out[count++] = {negated(swing.row), joint.max_swing - swing.angle, BoundRow::Side::kCone};
  }
  return count;
}

void keep_bound_impulse(Joint& joint, BoundRow::Side side, double impulse) {
  switch (side) {
    case BoundRow::Side::kLower:
      joint.limit_impulse = impulse;
      break;
    case BoundRow::Side::kUpper:
      joint.limit_impulse = -impulse;
      break;
    case BoundRow::Side::kCone:
      joint.swing_impulse = impulse;
      break;
  }
}

void correct_axial(const Joint& joint, SolverBody* a, SolverBody* b, Pose* pose_a, Pose* pose_b) {
  const bool world_b = b == nullptr;
  const SolverBody& body_b = world_b ? kWorldBody : *b;
  Pose world;
  Pose* pb = world_b ? &world : pose_b;
  // A bound the poses are clearly within moves nothing: no exact angle (rough_atan2.h; libm's
  // arctangent was a twentieth of a pgs ragdoll pile's step, most of it here).
  if (has_cone(joint) && !clearly_within_cone(joint, pose_a->orientation, pb->orientation, 0)) {
    const Swing swing = swing_of(joint, pose_a->orientation, pb->orientation);
    const double over = swing.angle - joint.max_swing;
    const double mass = swing.exists && over > 0 ? row_mass(swing.row, *a, body_b) : 0;
    if (mass > 0) displace_row(swing.row, -over / mass, a, b, pose_a, pose_b);
  }
  if (!joint.limit.enabled || clearly_within_limit(joint, pose_a->orientation, pb->orientation, 0))
    return;
  const FreeCoordinate c = free_coordinate(joint, *pose_a, *pb, world_b);
  if (!c.exists) return;
  double error = 0;  // the coordinate's distance past its bound, signed as the coordinate
  if (c.position < joint.limit.lower || joint.limit.lower == joint.limit.upper)
    error = c.position - joint.limit.lower;
  else if (c.position > joint.limit.upper)
    error = c.position - joint.limit.upper;
  if (error == 0) return;
  const double mass = row_mass(c.row, *a, body_b);
  if (mass > 0) displace_row(c.row, -error / mass, a, b, pose_a, pose_b);
}

JointReading read_axial(const Joint& joint, const Pose& pose_a, const Pose& pose_b,
                        const SolverBody& a, const SolverBody& b, bool world_b) {
  JointReading reading;
  const FreeCoordinate c = free_coordinate(joint, pose_a, pose_b, world_b);
  if (!c.exists) return reading;
  reading.position = c.position;
  reading.speed = row_rate(c.row, a, b);
  if (joint.impulse_time > 0) {
    reading.effort = impulse_along(joint) / joint.impulse_time;
  }
  return reading;
}

}  // namespace tumble
