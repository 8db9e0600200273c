#include "peers/joint_forest.h"

namespace tumble::bench {

bool place(const SceneDef& scene, std::vector<Placement>* placements, std::string* why_not) {
  const std::size_t n = scene.bodies.size();
  for (const BodyDef& def : scene.bodies)
    if (def.type == BodyType::kKinematic) {
      *why_not = "kinematic bodies are not mapped to this peer";
      return false;
    }
  std::vector<Placement>& at = *placements;
  at.assign(n, {});
  for (std::size_t i = 0; i < n; ++i)
    at[i].placed = scene.bodies[i].type == BodyType::kStatic;
  auto placed = [&](std::optional<std::size_t> i) { return !i || at[*i].placed; };
  std::vector<bool> used(scene.joints.size(), false);
  for (std::size_t left = scene.joints.size(); left > 0;) {
    bool grew = false;
    for (std::size_t j = 0; j < scene.joints.size(); ++j) {
      if (used[j]) continue;
      const SceneJoint& joint = scene.joints[j];
      const std::optional<std::size_t> a = joint.a, b = joint.b;
      if (placed(a) && placed(b)) {
        *why_not = "a loop of joints is not a tree";
        return false;
      }
      if (!placed(a) && !placed(b)) continue;
      const std::size_t child = placed(a) ? *b : *a;
      const std::optional<std::size_t> parent = placed(a) ? a : b;
      at[child] = {
          parent && scene.bodies[*parent].type != BodyType::kStatic ? parent : std::nullopt, j,
          true};
      used[j] = true;
      --left;
      grew = true;
    }
    if (grew || left == 0) continue;
    for (std::size_t j = 0; j < scene.joints.size() && !grew; ++j)
      if (!used[j]) {
        at[scene.joints[j].a].placed = true;  // a free root
        grew = true;
      }
  }
  return true;
}

int depth_of(const std::vector<Placement>& placements, std::size_t i) {
  int depth = 0;
  for (std::optional<std::size_t> up = placements[i].parent; up; up = placements[*up].parent)
    ++depth;
  return depth;
}

}  // namespace tumble::bench
