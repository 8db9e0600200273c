#include "physics/joint.h"

#include <cmath>

namespace tumble {
namespace {

bool finite(const Vec3& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

}  // namespace

Status validate(const JointDef& def) {
  switch (def.kind) {
    case JointKind::kBall:
    case JointKind::kHinge:
    case JointKind::kFixed:
    case JointKind::kDistance:
      break;
    default:
      return Status::error("kind: not a joint kind");
  }
  if (!def.a.is_valid()) return Status::error("a: must name a body");
  if (def.b.is_valid() && def.b == def.a) return Status::error("b: must differ from a");
  if (!finite(def.anchor)) return Status::error("anchor: must be finite");
  if (!finite(def.anchor_b)) return Status::error("anchor_b: must be finite");
  if (def.kind == JointKind::kHinge) {
    if (!finite(def.axis)) return Status::error("axis: must be finite");
    if (!(def.axis.norm() > 1e-9)) return Status::error("axis: must not be zero");
  }
  if (def.kind == JointKind::kDistance) {
    if (!(std::isfinite(def.length) && def.length >= 0))
      return Status::error("length: must be finite and >= 0");
    const double length = def.length > 0 ? def.length : (def.anchor_b - def.anchor).norm();
    if (!(length > 0))
      return Status::error("length: the anchors coincide; give a length or separate them");
  }
  return Status::ok();
}

}  // namespace tumble
