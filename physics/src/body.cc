#include <Eigen/Eigenvalues>
#include <cmath>
#include <string>

#include "body_state.h"

namespace tumble {
namespace {

Status check_vector(const Vec3& v, const char* field) {
  for (int k = 0; k < 3; ++k)
    if (!is_finite(v[k]))
      return Status::error(std::string(field) + "[" + std::to_string(k) + "]: must be finite");
  return Status::ok();
}

}  // namespace

Status validate(const BodyDef& def) {
  if (std::holds_alternative<HalfSpaceDef>(def.shape) && def.type != BodyType::kStatic)
    return Status::error("type: a half_space must be static");
  if (std::holds_alternative<HeightFieldDef>(def.shape) && def.type != BodyType::kStatic)
    return Status::error("type: a heightfield must be static");
  if (std::holds_alternative<TriangleMeshDef>(def.shape) && def.type != BodyType::kStatic)
    return Status::error("type: a mesh must be static");
  if (Status s = check_vector(def.position, "position"); !s) return s;
  if (!is_finite(def.orientation)) return Status::error("orientation: must be finite");
  const double norm = def.orientation.norm();
  if (std::abs(norm - 1) > 1e-3)
    return Status::error("orientation: must be a unit quaternion (norm is " + std::to_string(norm) +
                         ")");
  if (Status s = check_vector(def.linear_velocity, "linear_velocity"); !s) return s;
  if (Status s = check_vector(def.angular_velocity, "angular_velocity"); !s) return s;
  if (!is_finite(def.mass) || def.mass < 0) return Status::error("mass: must be finite and >= 0");
  if (def.type == BodyType::kDynamic && def.mass == 0 &&
      !(def.density > 0 && is_finite(def.density)))
    return Status::error("density: must be finite and > 0 when mass is 0");
  if (!is_finite(def.friction) || def.friction < 0)
    return Status::error("friction: must be finite and >= 0");
  if (!is_finite(def.restitution) || def.restitution < 0 || def.restitution > 1)
    return Status::error("restitution: must be in [0, 1]");
  if (Status s = check_own_forces(def.gravity_scale, def.linear_damping, def.angular_damping); !s)
    return s;
  if (Status s = check_vector(def.force, "force"); !s) return s;
  if (Status s = check_vector(def.torque, "torque"); !s) return s;
  if (def.type == BodyType::kStatic && !(def.force.isZero(0) && def.torque.isZero(0)))
    return Status::error("force: a static body does not move");
  if (def.type == BodyType::kKinematic) {
    if (Status s = check_kinematic_motion(def.force, def.torque, def.gravity_scale,
                                          def.linear_damping, def.angular_damping);
        !s)
      return s;
  }
  if (def.type == BodyType::kStatic &&
      !(def.linear_velocity.isZero(0) && def.angular_velocity.isZero(0)))
    return Status::error("linear_velocity: a static body does not move (a kinematic one does)");
  return Status::ok();
}

Status check_own_forces(double gravity_scale, double linear_damping, double angular_damping) {
  if (!(std::abs(gravity_scale) <= kMaxGravityScale))
    return Status::error("gravity_scale: must be finite with |x| <= 1000");
  if (!(linear_damping >= 0 && linear_damping <= kMaxDamping))
    return Status::error("linear_damping: must be in [0, 1e6] (1/s)");
  if (!(angular_damping >= 0 && angular_damping <= kMaxDamping))
    return Status::error("angular_damping: must be in [0, 1e6] (1/s)");
  return Status::ok();
}

Status check_kinematic_motion(const Vec3& force, const Vec3& torque, double gravity_scale,
                             double linear_damping, double angular_damping) {
  constexpr const char* kOnlyVelocity = ": a kinematic body moves only by the velocity given it";
  if (!force.isZero(0)) return Status::error(std::string("force") + kOnlyVelocity);
  if (!torque.isZero(0)) return Status::error(std::string("torque") + kOnlyVelocity);
  if (gravity_scale != 1) return Status::error(std::string("gravity_scale") + kOnlyVelocity);
  if (linear_damping != 0) return Status::error(std::string("linear_damping") + kOnlyVelocity);
  if (angular_damping != 0) return Status::error(std::string("angular_damping") + kOnlyVelocity);
  return Status::ok();
}

Result<Body> make_body(const BodyDef& def) {
  if (Status s = validate(def); !s) return s;
  Result<Shape> shape = Shape::create(def.shape);
  if (!shape) return shape.status().within("shape.");

  Body body;
  body.type = def.type;
  body.orientation = def.orientation.normalized();
  body.linear_velocity = def.linear_velocity;
  body.angular_velocity = def.angular_velocity;
  body.friction = def.friction;
  body.restitution = def.restitution;
  body.gravity_scale = def.gravity_scale;
  body.linear_damping = def.linear_damping;
  body.angular_damping = def.angular_damping;
  body.force = def.force;
  body.torque = def.torque;
  body.filter = def.filter;
  body.refresh_own_forces();

  const double density = def.mass > 0 ? def.mass / shape.value().volume() : def.density;
  MassProperties props = shape.value().mass_properties(
      def.type == BodyType::kStatic && !std::isfinite(shape.value().volume()) ? 1.0 : density);
  body.shape = shape.value().recentred(props.center_of_mass);
  body.position = def.position + body.orientation * props.center_of_mass;

  if (def.type == BodyType::kDynamic) {
    if (!(props.mass > 0) || !std::isfinite(props.mass))
      return Status::error("mass: the shape's mass is not a positive number");
    body.mass = props.mass;
    body.inverse_mass = 1.0 / props.mass;
    body.inertia_body = props.inertia;
    body.inverse_inertia_body = props.inertia.inverse();
    if (!body.inverse_inertia_body.allFinite())
      return Status::error("shape: its inertia tensor is singular");
    const Mat3 spherical = Mat3::Identity() * (props.inertia.trace() / 3);
    body.spherical_inertia = (props.inertia - spherical).norm() <= 1e-12 * props.inertia.norm();
    body.refresh_symmetric_top();
  }
  body.update_world_inertia();
  return body;
}

void Body::refresh_symmetric_top() {
  symmetric_axis.setZero();
  symmetric_spin_ratio = 0;
  if (!is_dynamic() || spherical_inertia || !inertia_body.allFinite()) return;
  // Moments within this fraction of the largest count as equal: the torque the difference would
  // give is that fraction of the gyroscopic torque, far below the step's own error.
  const auto equal = [&](double a, double b, double largest) {
    return std::abs(a - b) <= 1e-12 * largest;
  };
  const auto set = [&](const Vec3& axis, double along, double across) {
    if (!(across > 0)) return;
    symmetric_axis = axis.normalized();
    symmetric_spin_ratio = (across - along) / across;
  };
  const Vec3 d = inertia_body.diagonal();
  if (inertia_body.isDiagonal(0)) {
    // The principal axes are the body's own (boxes, capsules, cylinders as made): the axis exact.
    const double largest = d.maxCoeff();
    for (int k = 0; k < 3; ++k) {
      const int i = (k + 1) % 3, j = (k + 2) % 3;
      if (equal(d[i], d[j], largest) && !equal(d[k], d[i], largest)) {
        set(Vec3::Unit(k), d[k], 0.5 * (d[i] + d[j]));
        return;
      }
    }
    return;
  }
  Eigen::SelfAdjointEigenSolver<Mat3> solver(inertia_body);
  if (solver.info() != Eigen::Success) return;
  const Vec3 moments = solver.eigenvalues();  // ascending
  const double largest = moments[2];
  if (equal(moments[0], moments[1], largest) && !equal(moments[1], moments[2], largest)) {
    set(solver.eigenvectors().col(2), moments[2], 0.5 * (moments[0] + moments[1]));
  } else if (equal(moments[1], moments[2], largest) && !equal(moments[0], moments[1], largest)) {
    set(solver.eigenvectors().col(0), moments[0], 0.5 * (moments[1] + moments[2]));
  }
}

Result<MassProperties> body_mass_properties(const BodyDef& def) {
  Result<Body> body = make_body(def);
  if (!body) return body.status();
  MassProperties props;
  props.mass = body.value().mass;
  props.inertia = body.value().inertia_body;
  if (!body.value().is_static() || std::isfinite(body.value().shape.volume()))
    props.center_of_mass = Shape::create(def.shape).value().mass_properties(1.0).center_of_mass;
  return props;
}

}  // namespace tumble
