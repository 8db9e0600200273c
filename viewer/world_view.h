// What the viewer knows of the world: the bodies' shapes and colours from the stream's
// descriptions, their latest poses, and from those the instances to draw. Fed with frames only;
// knows nothing of the engine.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <unordered_map>
#include <vector>

#include "height_field_mesh.h"
#include "hull_mesh.h"
#include "renderer.h"
#include "surface_mesh.h"
#include "tumble/v1/world.pb.h"

namespace tumble::viewer {

class WorldView {
 public:
  // Takes a frame: descriptions of added bodies, removals, and every pose in it.
  void apply(const v1::Frame& frame);
  // The bodies as instances by the renderer's mesh handles (capsules get meshes of their own on
  // first sight).
  std::vector<std::vector<Instance>> instances(Renderer& renderer);
  // The last frame's contacts, when the stream carries them, for Renderer::draw's overlay (drawn
  // over the bodies, so that points inside a pile show): each point a red ball, its normal a
  // white rod. Sized to the scene: the ball's radius is 1.5% of the radius of the sphere around the
  // bodies (at least 5 mm), the rod five times that.
  std::vector<std::vector<Instance>> contact_overlay(Renderer& renderer) const;
  // The last frame's joints, when the stream carries them: each anchor a yellow ball, its axis a
  // yellow rod through it, sized as the contacts' overlay (twice as large).
  std::vector<std::vector<Instance>> joint_overlay(Renderer& renderer) const;
  // A sphere around the bodies that move and the statics of finite size (not the ground), or
  // nothing before the first frame with such bodies.
  std::optional<std::pair<Eigen::Vector3f, float>> bounds() const;
  float overlay_ball() const;

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
  // One shape's instances (a compound's parts, each with its own model matrix).
  void add_shape(Renderer& renderer, std::uint64_t id, int part, const v1::Shape& shape,
                 const Eigen::Affine3f& placed, const Instance& look,
                 std::vector<std::vector<Instance>>* out);
  std::map<std::pair<float, float>, int> capsule_meshes_;
  // By body id and part (-1: the body itself): each hull its own mesh.
  std::map<std::pair<std::uint64_t, int>, int> hull_meshes_;
  std::unordered_map<std::uint64_t, int> height_field_meshes_;  // the same for heightfields
  std::unordered_map<std::uint64_t, int> surface_meshes_;       // and for triangle meshes
  v1::Contacts contacts_;
  v1::JointStates joints_;
  // Each body's place in the order bodies were described, counted from the last time the view
  // held none: a colour follows it, so a world reset (new ids, the same bodies) keeps its colours.
  std::unordered_map<std::uint64_t, std::uint64_t> ordinals_;
  std::uint64_t next_ordinal_ = 0;
  std::uint64_t step_ = 0;
  double time_ = 0;
};

// Adds an instance of `mesh` to a list of instances by mesh.
void add_instance(int mesh, const Instance& instance, std::vector<std::vector<Instance>>* out);
// Appends an overlay's instances to another's, mesh by mesh.
void add_overlay(const std::vector<std::vector<Instance>>& more,
                 std::vector<std::vector<Instance>>* overlay);

// 0xRRGGBBAA as RGBA in [0, 1]; 0 picks a colour from a fixed palette by the body's ordinal.
Eigen::Vector4f body_colour(std::uint32_t rgba, std::uint64_t ordinal, bool is_static);

// The camera moved back along its line of sight (or forward) so that the sphere fills the
// picture's height, looking at its centre.
Camera framed(const Camera& camera, const Eigen::Vector3f& centre, float radius);

}  // namespace tumble::viewer
