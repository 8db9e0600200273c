// Where each body of a scene hangs in a tree of joints, for the peers that model joints in
// generalised coordinates (MuJoCo's nested bodies, Bullet's btMultiBody): its parent body (none:
// the world) and the joint that holds it there (none: a free body, or the root of a tree).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "scenes/scene.h"

namespace tumble::bench {

struct Placement {
  std::optional<std::size_t> parent, joint;
  bool placed = false;  // while the tree grows (place)
};

// Grows the trees from the world (static bodies are the world) through the joints; a joint whose
// bodies are both placed already closes a loop (refused, with the reason). Bodies the world does
// not reach through joints become free roots, lowest index first, and the growth goes on from
// them. Kinematic bodies are refused.
bool place(const SceneDef& scene, std::vector<Placement>* placements, std::string* why_not);

// The depth of body i below its root (0: a root).
int depth_of(const std::vector<Placement>& placements, std::size_t i);

}  // namespace tumble::bench
