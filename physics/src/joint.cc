#include "physics/joint.h"

#include <cmath>
#include <numbers>

namespace tumble {
namespace {

bool finite(const Vec3& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

bool has_axis(JointKind kind) {
  return kind == JointKind::kHinge || kind == JointKind::kSlider || kind == JointKind::kBall;
}

}  // namespace

Status validate(JointKind kind, const JointLimit& limit) {
  if (!limit.enabled) return Status::ok();
  if (kind == JointKind::kFixed) return Status::error("limit: a fixed joint has none");
  if (!(std::isfinite(limit.lower) && std::isfinite(limit.upper)))
    return Status::error("limit: lower and upper must be finite");
  if (!(limit.lower <= limit.upper)) return Status::error("limit: lower must not exceed upper");
  constexpr double kPi = std::numbers::pi;
  if ((kind == JointKind::kHinge || kind == JointKind::kBall) &&
      !(limit.lower >= -kPi && limit.upper <= kPi))
    return Status::error("limit: an angle's bounds lie within [-pi, pi]");
  if (kind == JointKind::kDistance && !(limit.lower >= 0))
    return Status::error("limit: a length's lower bound must be >= 0");
  return Status::ok();
}

Status validate(JointKind kind, const JointMotor& motor) {
  if (!motor.enabled) return Status::ok();
  if (kind != JointKind::kHinge && kind != JointKind::kSlider)
    return Status::error("motor: only hinges and sliders have one");
  if (!std::isfinite(motor.speed)) return Status::error("motor.speed: must be finite");
  if (!(motor.max_force >= 0 && motor.max_force <= kMaxJointForce))
    return Status::error("motor.max_force: must be in [0, 1e20]");
  return Status::ok();
}

Status validate(JointKind kind, const JointSpring& spring) {
  if (!spring.enabled) return Status::ok();
  if (kind != JointKind::kHinge && kind != JointKind::kSlider && kind != JointKind::kDistance)
    return Status::error("spring: only hinges, sliders and distance joints have one");
  if (!std::isfinite(spring.target)) return Status::error("spring.target: must be finite");
  if (kind == JointKind::kDistance && spring.target != 0)
    return Status::error("spring.target: a distance joint's spring rests at its length; leave 0");
  if (!(spring.stiffness >= 0 && spring.stiffness <= kMaxJointForce))
    return Status::error("spring.stiffness: must be in [0, 1e20]");
  if (!(spring.damping >= 0 && spring.damping <= kMaxJointForce))
    return Status::error("spring.damping: must be in [0, 1e20]");
  if (!(spring.stiffness + spring.damping > 0))
    return Status::error("spring: stiffness or damping must be above 0");
  return Status::ok();
}

Status validate(const JointDef& def) {
  switch (def.kind) {
    case JointKind::kBall:
    case JointKind::kHinge:
    case JointKind::kFixed:
    case JointKind::kDistance:
    case JointKind::kSlider:
      break;
    default:
      return Status::error("kind: not a joint kind");
  }
  if (!def.a.is_valid()) return Status::error("a: must name a body");
  if (def.b.is_valid() && def.b == def.a) return Status::error("b: must differ from a");
  if (!finite(def.anchor)) return Status::error("anchor: must be finite");
  if (!finite(def.anchor_b)) return Status::error("anchor_b: must be finite");
  if (has_axis(def.kind)) {
    if (!finite(def.axis)) return Status::error("axis: must be finite");
    if (!(def.axis.stableNorm() > 1e-9)) return Status::error("axis: must not be zero");
  }
  if (def.kind == JointKind::kDistance) {
    if (!(std::isfinite(def.length) && def.length >= 0))
      return Status::error("length: must be finite and >= 0");
    const double length = def.length > 0 ? def.length : (def.anchor_b - def.anchor).norm();
    if (!(length > 0))
      return Status::error("length: the anchors coincide; give a length or separate them");
  }
  if (!(def.max_swing > 0 && def.max_swing <= std::numbers::pi))
    return Status::error("max_swing: must be in (0, pi]");
  if (def.kind != JointKind::kBall && def.max_swing < std::numbers::pi)
    return Status::error("max_swing: only a ball joint has a swing cone");
  if (def.kind == JointKind::kBall && def.limit.enabled && def.max_swing >= std::numbers::pi - 1e-3)
    return Status::error("limit: a ball's twist needs a swing cone (max_swing) below pi");
  if (Status s = validate_friction(def.kind, def.friction); !s) return s;
  if (Status s = validate(def.kind, def.limit); !s) return s;
  if (Status s = validate(def.kind, def.motor); !s) return s;
  return validate(def.kind, def.spring);
}

Status validate_friction(JointKind kind, double friction) {
  if (!(std::isfinite(friction) && friction >= 0 && friction <= kMaxJointForce))
    return Status::error("friction: must be finite, >= 0 and <= 1e20");
  if (friction > 0 && (kind == JointKind::kFixed || kind == JointKind::kDistance))
    return Status::error("friction: only ball, hinge and slider joints have friction");
  return Status::ok();
}

}  // namespace tumble
