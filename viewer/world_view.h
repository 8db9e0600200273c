// What the viewer knows of the world: the bodies' shapes and colours from the stream's
// descriptions, their latest poses, and from those the instances to draw. Fed with frames only;
// knows nothing of the engine.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <unordered_map>
#include <vector>

#include "hull_mesh.h"
#include "renderer.h"
#include "tumble/v1/world.pb.h"

namespace tumble::viewer {

class WorldView {
 public:
  // Takes a frame: descriptions of added bodies, removals, and every pose in it.
  void apply(const v1::Frame& frame);
  // Instances by the renderer's mesh handles (capsules get meshes of their own on first sight).
  // With `contacts`, the last frame's contact points (small red balls) and normals (thin white
  // rods, 0.2 m from the point along the normal) are added, when the stream carries them.
  std::vector<std::vector<Instance>> instances(Renderer& renderer, bool contacts = false);

  std::uint64_t step() const { return step_; }
  double time() const { return time_; }
  std::size_t body_count() const { return poses_.size(); }
  // The first dynamic body after `id` in id order (wrapping), or 0 when there is none.
  std::uint64_t next_dynamic_body(std::uint64_t id) const;
  std::optional<Eigen::Vector3f> position_of(std::uint64_t id) const;

 private:
  struct Pose {
    Eigen::Vector3f position = Eigen::Vector3f::Zero();
    Eigen::Quaternionf orientation = Eigen::Quaternionf::Identity();
  };
  std::unordered_map<std::uint64_t, v1::BodyDescription> looks_;
  std::map<std::uint64_t, Pose> poses_;  // ordered: the same draw order every frame
  std::map<std::pair<float, float>, int> capsule_meshes_;
  std::unordered_map<std::uint64_t, int> hull_meshes_;  // by body id: each hull its own mesh
  v1::Contacts contacts_;
  std::uint64_t step_ = 0;
  double time_ = 0;
};

// 0xRRGGBBAA as RGBA in [0, 1]; 0 picks a colour from a fixed palette by the body's id.
Eigen::Vector4f body_colour(std::uint32_t rgba, std::uint64_t id, bool is_static);

}  // namespace tumble::viewer
