#include "world_view.h"

#include <algorithm>
#include <cmath>

namespace tumble::viewer {

Eigen::Vector4f body_colour(std::uint32_t rgba, std::uint64_t ordinal, bool is_static) {
  if (rgba != 0)
    return {static_cast<float>(rgba >> 24 & 0xFF) / 255,
            static_cast<float>(rgba >> 16 & 0xFF) / 255, static_cast<float>(rgba >> 8 & 0xFF) / 255,
            static_cast<float>(rgba & 0xFF) / 255};
  if (is_static) return {0.55f, 0.57f, 0.55f, 1};
  static const Eigen::Vector4f palette[] = {{0.90f, 0.45f, 0.20f, 1}, {0.25f, 0.55f, 0.85f, 1},
                                            {0.35f, 0.70f, 0.35f, 1}, {0.85f, 0.75f, 0.25f, 1},
                                            {0.65f, 0.40f, 0.75f, 1}, {0.85f, 0.35f, 0.40f, 1}};
  return palette[ordinal % std::size(palette)];
}

Camera framed(const Camera& camera, const Eigen::Vector3f& centre, float radius) {
  Camera out = camera;
  Eigen::Vector3f back = camera.eye - camera.target;
  if (back.norm() < 1e-6f) back = Eigen::Vector3f(0.5f, -0.75f, 0.4f);
  const float half_fov = 0.5f * camera.fov_y_degrees * static_cast<float>(M_PI) / 180;
  // 10% of margin; never inside the sphere.
  const float distance = std::max(1.1f * radius / std::sin(half_fov), radius + camera.near_plane);
  out.target = centre;
  out.eye = centre + distance * back.normalized();
  return out;
}

namespace {

// How far a shape reaches from its body's origin (a hull's is taken as half a metre).
float reach_of(const v1::Shape& shape) {
  if (shape.has_box())
    return 0.5f * Eigen::Vector3f(static_cast<float>(shape.box().size().x()),
                                  static_cast<float>(shape.box().size().y()),
                                  static_cast<float>(shape.box().size().z()))
                      .norm();
  if (shape.has_sphere()) return static_cast<float>(shape.sphere().radius());
  if (shape.has_capsule())
    return static_cast<float>(shape.capsule().radius() + shape.capsule().half_height());
  if (shape.has_compound()) {
    float reach = 0;
    for (const v1::CompoundPart& part : shape.compound().parts())
      if (!part.shape().has_compound())
        reach = std::max(reach,
                         static_cast<float>(std::sqrt(part.position().x() * part.position().x() +
                                                      part.position().y() * part.position().y() +
                                                      part.position().z() * part.position().z())) +
                             reach_of(part.shape()));
    return reach;
  }
  return 0.5f;
}

}  // namespace

std::optional<std::pair<Eigen::Vector3f, float>> WorldView::bounds() const {
  Eigen::Vector3f low = Eigen::Vector3f::Constant(INFINITY), high = -low;
  for (const auto& [id, pose] : poses_) {
    const auto look = looks_.find(id);
    if (look == looks_.end() || look->second.shape().has_plane() ||
        look->second.shape().has_heightfield() || look->second.shape().has_mesh())
      continue;  // the ground frames the bodies on it, not itself
    const float reach = reach_of(look->second.shape());
    low = low.cwiseMin(pose.position - Eigen::Vector3f::Constant(reach));
    high = high.cwiseMax(pose.position + Eigen::Vector3f::Constant(reach));
  }
  if (!(low.x() <= high.x())) return std::nullopt;
  return std::pair{0.5f * (low + high), std::max(0.5f * (high - low).norm(), 0.1f)};
}

std::uint64_t WorldView::next_dynamic_body(std::uint64_t id) const {
  auto is_dynamic = [&](std::uint64_t candidate) {
    const auto look = looks_.find(candidate);
    return look != looks_.end() && look->second.type() == v1::BODY_TYPE_DYNAMIC;
  };
  for (auto it = poses_.upper_bound(id); it != poses_.end(); ++it)
    if (is_dynamic(it->first)) return it->first;
  for (const auto& [candidate, pose] : poses_)
    if (is_dynamic(candidate)) return candidate;
  return 0;
}

std::optional<Eigen::Vector3f> WorldView::position_of(std::uint64_t id) const {
  const auto pose = poses_.find(id);
  if (pose == poses_.end()) return std::nullopt;
  return pose->second.position;
}

void WorldView::apply(const v1::Frame& frame) {
  step_ = frame.step();
  time_ = frame.time();
  for (std::uint64_t id : frame.removed()) {
    looks_.erase(id);
    poses_.erase(id);
    ordinals_.erase(id);
  }
  if (looks_.empty()) next_ordinal_ = 0;
  for (const v1::BodyDescription& d : frame.added()) {
    looks_[d.id()] = d;
    if (ordinals_.emplace(d.id(), next_ordinal_).second) ++next_ordinal_;
  }
  contacts_ = frame.contacts();
  joints_ = frame.joints();
  const int n = frame.ids_size();
  if (frame.positions_size() != 3 * n || frame.orientations_size() != 4 * n) return;
  for (int i = 0; i < n; ++i) {
    Pose& pose = poses_[frame.ids(i)];
    pose.position = {static_cast<float>(frame.positions(3 * i)),
                     static_cast<float>(frame.positions(3 * i + 1)),
                     static_cast<float>(frame.positions(3 * i + 2))};
    pose.orientation = Eigen::Quaternionf(static_cast<float>(frame.orientations(4 * i)),
                                          static_cast<float>(frame.orientations(4 * i + 1)),
                                          static_cast<float>(frame.orientations(4 * i + 2)),
                                          static_cast<float>(frame.orientations(4 * i + 3)));
    pose.orientation.normalize();
  }
}

std::vector<std::vector<Instance>> WorldView::instances(Renderer& renderer) {
  std::vector<std::vector<Instance>> out(3);
  for (const auto& [id, pose] : poses_) {
    const auto look = looks_.find(id);
    if (look == looks_.end()) continue;  // not described yet
    const v1::BodyDescription& d = look->second;
    Instance instance;
    const auto ordinal = ordinals_.find(id);
    instance.colour = body_colour(d.color(), ordinal != ordinals_.end() ? ordinal->second : id,
                                  d.type() == v1::BODY_TYPE_STATIC);
    const Eigen::Affine3f placed = Eigen::Translation3f(pose.position) * pose.orientation;
    add_shape(renderer, id, -1, d.shape(), placed, instance, &out);
  }
  return out;
}

void WorldView::add_shape(Renderer& renderer, std::uint64_t id, int part, const v1::Shape& shape,
                          const Eigen::Affine3f& placed, const Instance& look,
                          std::vector<std::vector<Instance>>* out) {
  const auto add = [&](int mesh, const Instance& instance) { add_instance(mesh, instance, out); };
  Instance instance = look;
  Eigen::Affine3f model = placed;
  switch (shape.kind_case()) {
    case v1::Shape::kBox: {
      const v1::Vec3& size = shape.box().size();
      model.scale(Eigen::Vector3f(size.x(), size.y(), size.z()) / 2);
      instance.model = model.matrix();
      add(renderer.box_mesh(), instance);
      break;
    }
    case v1::Shape::kSphere:
      model.scale(static_cast<float>(shape.sphere().radius()));
      instance.model = model.matrix();
      add(renderer.sphere_mesh(), instance);
      break;
    case v1::Shape::kCapsule: {
      const std::pair<float, float> key{static_cast<float>(shape.capsule().radius()),
                                        static_cast<float>(shape.capsule().half_height())};
      auto mesh = capsule_meshes_.find(key);
      if (mesh == capsule_meshes_.end())
        mesh =
            capsule_meshes_.emplace(key, renderer.add_mesh(capsule(key.first, key.second))).first;
      instance.model = model.matrix();
      add(mesh->second, instance);
      break;
    }
    case v1::Shape::kPlane:
      model.scale(Eigen::Vector3f(200, 200, 1));  // the ground, as far as the eye goes
      instance.model = model.matrix();
      instance.material.x() = 1;  // a metre grid
      add(renderer.ground_mesh(), instance);
      break;
    case v1::Shape::kHull: {
      auto mesh = hull_meshes_.find({id, part});
      if (mesh == hull_meshes_.end())
        mesh = hull_meshes_
                   .emplace(std::pair{id, part},
                            renderer.add_mesh(hull_mesh(std::span<const double>(
                                shape.hull().points().data(),
                                static_cast<std::size_t>(shape.hull().points_size())))))
                   .first;
      instance.model = model.matrix();
      add(mesh->second, instance);
      break;
    }
    case v1::Shape::kHeightfield: {
      auto mesh = height_field_meshes_.find(id);
      if (mesh == height_field_meshes_.end()) {
        const v1::HeightField& f = shape.heightfield();
        mesh =
            height_field_meshes_
                .emplace(id,
                         renderer.add_mesh(height_field_mesh(
                             f.samples_x(), f.samples_y(), f.spacing_x(), f.spacing_y(),
                             std::span<const double>(f.heights().data(),
                                                     static_cast<std::size_t>(f.heights_size())))))
                .first;
      }
      instance.model = model.matrix();
      add(mesh->second, instance);
      break;
    }
    case v1::Shape::kMesh: {
      auto mesh = surface_meshes_.find(id);
      if (mesh == surface_meshes_.end()) {
        const v1::Mesh& m = shape.mesh();
        mesh =
            surface_meshes_
                .emplace(
                    id,
                    renderer.add_mesh(surface_mesh(
                        std::span<const double>(m.vertices().data(),
                                                static_cast<std::size_t>(m.vertices_size())),
                        std::span<const std::uint32_t>(
                            m.triangles().data(), static_cast<std::size_t>(m.triangles_size())))))
                .first;
      }
      instance.model = model.matrix();
      add(mesh->second, instance);
      break;
    }
    case v1::Shape::kCompound:
      // Each part in the same colour, placed in the body's frame (a part is never a compound).
      if (part >= 0) break;
      for (int i = 0; i < shape.compound().parts_size(); ++i) {
        const v1::CompoundPart& p = shape.compound().parts(i);
        const v1::Quat& q = p.orientation();
        const Eigen::Quaternionf turn =
            p.has_orientation()
                ? Eigen::Quaternionf(static_cast<float>(q.w()), static_cast<float>(q.x()),
                                     static_cast<float>(q.y()), static_cast<float>(q.z()))
                      .normalized()
                : Eigen::Quaternionf::Identity();
        const Eigen::Vector3f at(static_cast<float>(p.position().x()),
                                 static_cast<float>(p.position().y()),
                                 static_cast<float>(p.position().z()));
        add_shape(renderer, id, i, p.shape(), placed * Eigen::Translation3f(at) * turn, look, out);
      }
      break;
    default:
      break;
  }
}

// An overlay's ball: 1.5% of the radius of the sphere around the bodies, at least 5 mm.
float WorldView::overlay_ball() const {
  const auto around = bounds();
  return std::max(0.015f * (around ? around->second : 1.0f), 0.005f);
}

std::vector<std::vector<Instance>> WorldView::contact_overlay(Renderer& renderer) const {
  std::vector<std::vector<Instance>> out;
  const auto add = [&](int mesh, const Instance& instance) { add_instance(mesh, instance, &out); };
  const float ball = overlay_ball();
  const int points = contacts_.body_a_size();
  if (contacts_.points_size() != 3 * points || contacts_.normals_size() != 3 * points) return out;
  for (int i = 0; i < points; ++i) {
    const Eigen::Vector3f p(static_cast<float>(contacts_.points(3 * i)),
                            static_cast<float>(contacts_.points(3 * i + 1)),
                            static_cast<float>(contacts_.points(3 * i + 2)));
    const Eigen::Vector3f n = Eigen::Vector3f(static_cast<float>(contacts_.normals(3 * i)),
                                              static_cast<float>(contacts_.normals(3 * i + 1)),
                                              static_cast<float>(contacts_.normals(3 * i + 2)))
                                  .normalized();
    Instance point;
    point.model = (Eigen::Translation3f(p) * Eigen::Scaling(ball)).matrix();
    point.colour = {0.95f, 0.1f, 0.1f, 1};
    add(renderer.sphere_mesh(), point);
    // The rod: the unit cube squeezed to a third of the ball and stretched to five balls along
    // the normal.
    Instance rod;
    const Eigen::Quaternionf turn = Eigen::Quaternionf::FromTwoVectors(Eigen::Vector3f::UnitZ(), n);
    rod.model = (Eigen::Translation3f(p + 2.5f * ball * n) * turn *
                 Eigen::Scaling(Eigen::Vector3f(0.3f * ball, 0.3f * ball, 2.5f * ball)))
                    .matrix();
    rod.colour = {1, 1, 1, 1};
    add(renderer.box_mesh(), rod);
  }
  return out;
}

void add_instance(int mesh, const Instance& instance, std::vector<std::vector<Instance>>* out) {
  if (static_cast<std::size_t>(mesh) >= out->size()) out->resize(mesh + 1);
  (*out)[mesh].push_back(instance);
}

void add_overlay(const std::vector<std::vector<Instance>>& more,
                 std::vector<std::vector<Instance>>* overlay) {
  if (overlay->size() < more.size()) overlay->resize(more.size());
  for (std::size_t mesh = 0; mesh < more.size(); ++mesh)
    (*overlay)[mesh].insert((*overlay)[mesh].end(), more[mesh].begin(), more[mesh].end());
}

std::vector<std::vector<Instance>> WorldView::joint_overlay(Renderer& renderer) const {
  std::vector<std::vector<Instance>> out;
  const auto add = [&](int mesh, const Instance& instance) { add_instance(mesh, instance, &out); };
  const float ball = 2 * overlay_ball();
  const int joints = joints_.ids_size();
  if (joints_.anchors_size() != 3 * joints || joints_.axes_size() != 3 * joints) return out;
  const Eigen::Vector4f yellow{1.0f, 0.85f, 0.1f, 1};
  for (int i = 0; i < joints; ++i) {
    const Eigen::Vector3f p(static_cast<float>(joints_.anchors(3 * i)),
                            static_cast<float>(joints_.anchors(3 * i + 1)),
                            static_cast<float>(joints_.anchors(3 * i + 2)));
    Eigen::Vector3f axis(static_cast<float>(joints_.axes(3 * i)),
                         static_cast<float>(joints_.axes(3 * i + 1)),
                         static_cast<float>(joints_.axes(3 * i + 2)));
    if (!(axis.norm() > 0)) axis = Eigen::Vector3f::UnitZ();
    Instance point;
    point.model = (Eigen::Translation3f(p) * Eigen::Scaling(ball)).matrix();
    point.colour = yellow;
    add(renderer.sphere_mesh(), point);
    // The axis: the unit cube squeezed to a quarter ball and stretched four balls each way.
    Instance rod;
    const Eigen::Quaternionf turn =
        Eigen::Quaternionf::FromTwoVectors(Eigen::Vector3f::UnitZ(), axis.normalized());
    rod.model = (Eigen::Translation3f(p) * turn *
                 Eigen::Scaling(Eigen::Vector3f(0.25f * ball, 0.25f * ball, 4 * ball)))
                    .matrix();
    rod.colour = yellow;
    add(renderer.box_mesh(), rod);
  }
  return out;
}

}  // namespace tumble::viewer
