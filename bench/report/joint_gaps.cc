#include "joint_gaps.h"

#include <algorithm>
#include <cmath>

namespace tumble::report {

JointGaps::JointGaps(const SceneDef& scene) {
  std::vector<int> dynamic_index(scene.bodies.size(), -1);
  int next = 0;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i)
    if (scene.bodies[i].type == BodyType::kDynamic) dynamic_index[i] = next++;
  auto end_at = [&](std::optional<std::size_t> body, const Vec3& point) {
    End end;
    end.local = point;
    if (!body) return end;
    const BodyDef& def = scene.bodies[*body];
    end.body = dynamic_index[*body];
    end.local = end.body < 0 ? point : Vec3(def.orientation.conjugate() * (point - def.position));
    return end;
  };
  for (const SceneJoint& joint : scene.joints) {
    const JointDef& def = joint.def;
    Joint j{.kind = def.kind};
    j.a = end_at(joint.a, def.anchor);
    const bool distance = def.kind == JointKind::kDistance;
    j.b = end_at(joint.b, distance ? def.anchor_b : def.anchor);
    j.length = distance && def.length == 0 ? (def.anchor_b - def.anchor).norm() : def.length;
    const Vec3 axis = def.axis.normalized();
    j.axis_in_b = joint.b && j.b.body >= 0
                      ? Vec3(scene.bodies[*joint.b].orientation.conjugate() * axis)
                      : axis;
    joints_.push_back(j);
  }
}

Vec3 JointGaps::where(const bench::Simulation& sim, const End& end) const {
  if (end.body < 0) return end.local;
  const bench::BodyState s = sim.body(static_cast<std::size_t>(end.body));
  return s.position + s.orientation * end.local;
}

double JointGaps::largest(const bench::Simulation& sim) const {
  double largest = 0;
  for (const Joint& j : joints_) {
    const Vec3 apart = where(sim, j.a) - where(sim, j.b);
    double gap = apart.norm();
    if (j.kind == JointKind::kDistance) gap = std::abs(gap - j.length);
    if (j.kind == JointKind::kSlider) {
      const Vec3 axis =
          j.b.body < 0
              ? j.axis_in_b
              : Vec3(sim.body(static_cast<std::size_t>(j.b.body)).orientation * j.axis_in_b);
      gap = (apart - apart.dot(axis) * axis).norm();
    }
    if (!std::isfinite(gap)) return gap;
    largest = std::max(largest, gap);
  }
  return largest;
}

}  // namespace tumble::report
