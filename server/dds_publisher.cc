#include "dds_publisher.h"

#include <dds/dds.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <string>
#include <unordered_map>
#include <vector>

#include "physics/compound.h"
#include "tumble_qos.h"
#include "tumble_states.h"

namespace tumble::server {
namespace {

constexpr char kFrameId[] = "world";

using PoseArray = geometry_msgs_msg_dds__PoseArray_;
using Pose = geometry_msgs_msg_dds__Pose_;
using Point = geometry_msgs_msg_dds__Point_;
using Vector3 = geometry_msgs_msg_dds__Vector3_;
using PoseIds = tumble_msgs_msg_dds__BodyIds_;
using Contacts = tumble_msgs_msg_dds__Contacts_;
using Stats = tumble_msgs_msg_dds__StepStats_;
using BodySample = tumble_msgs_msg_dds__Body_;
using BodyPartSample = tumble_msgs_msg_dds__BodyPart_;
using Transform = geometry_msgs_msg_dds__TransformStamped_;
using TfMessage = tf2_msgs_msg_dds__TFMessage_;
using Clock = rosgraph_msgs_msg_dds__Clock_;
using Marker = visualization_msgs_msg_dds__Marker_;
using MarkerArray = visualization_msgs_msg_dds__MarkerArray_;
using JointStates = sensor_msgs_msg_dds__JointState_;

// visualization_msgs/Marker's types and actions.
constexpr std::int32_t kCube = 1, kSphere = 2, kCylinder = 3, kTriangleList = 11;
constexpr std::int32_t kAdd = 0, kDelete = 2;
constexpr char kEmpty[] = "";
constexpr char kMarkerNamespace[] = "tumble";
// The ground (a half-space) drawn as a slab this wide and this thin, its top at the surface.
constexpr double kGroundWidth = 200, kGroundThickness = 0.01;
constexpr double kMaxMarkerTriangles = 131072;  // a terrain's marker: at most about 10 MB

std_msgs_msg_dds__Header_ header_at(double time) {
  std_msgs_msg_dds__Header_ header;
  const double seconds = std::floor(time);
  header.stamp.sec = static_cast<std::int32_t>(seconds);
  header.stamp.nanosec =
      static_cast<std::uint32_t>(std::lround((time - seconds) * 1e9) % 1000000000);
  header.frame_id = const_cast<char*>(kFrameId);  // written, never freed: DDS copies it
  return header;
}

// A DDS sequence over our own buffer (DDS serialises it on write and never frees it).
template <class Sequence, class T>
Sequence view(std::vector<T>& items) {
  Sequence s;
  s._maximum = s._length = static_cast<std::uint32_t>(items.size());
  s._buffer = items.data();
  s._release = false;
  return s;
}

// A marker's id: the body's (ids stay far below 2^31 in any world a viewer shows).
std::int32_t marker_id(std::uint64_t id) {
  return static_cast<std::int32_t>(id % 2147483647u);
}

std_msgs_msg_dds__ColorRGBA_ colour_of(const BodyLook& look) {
  if (look.colour == 0)  // the viewer's choice: grey, darker when static
    return look.type == BodyType::kStatic ? std_msgs_msg_dds__ColorRGBA_{0.45f, 0.45f, 0.45f, 1}
                                          : std_msgs_msg_dds__ColorRGBA_{0.75f, 0.75f, 0.75f, 1};
  auto channel = [&](int shift) { return static_cast<float>((look.colour >> shift) & 0xFF) / 255; };
  return {channel(24), channel(16), channel(8), channel(0)};
}

// A marker with every string and sequence empty, as DDS must find them.
Marker empty_marker(const std_msgs_msg_dds__Header_& header) {
  Marker marker{};
  marker.header = header;
  marker.ns = const_cast<char*>(kMarkerNamespace);
  marker.texture_resource = marker.text = marker.mesh_resource = const_cast<char*>(kEmpty);
  marker.texture.header = header;
  marker.texture.format = const_cast<char*>(kEmpty);
  marker.mesh_file.filename = const_cast<char*>(kEmpty);
  return marker;
}

std::string dds_error(const char* what, dds_return_t code) {
  return std::string(what) + ": " + dds_strretcode(code);
}

// A compound's part as triangles in the body's frame: a box's or hull's faces, a round part's
// hull of its farthest points towards a 7 x 7 grid on each face of a cube.
void add_part_triangles(const Compound::Part& part, std::vector<Point>* out) {
  ConvexPolyhedron round;
  const ConvexPolyhedron* surface = part.shape.polyhedron();
  if (surface == nullptr) {
    std::vector<Vec3> points;
    for (int i = -3; i <= 3; ++i)
      for (int j = -3; j <= 3; ++j)
        for (int k : {-3, 3}) {  // the faces of a cube of directions: 98 of them
          points.push_back(part.shape.support(Vec3(i, j, k)));
          points.push_back(part.shape.support(Vec3(i, k, j)));
          points.push_back(part.shape.support(Vec3(k, i, j)));
        }
    Result<ConvexPolyhedron> built = build_convex_hull(points);
    if (!built) return;
    round = std::move(built).value();
    surface = &round;
  }
  for (const ConvexPolyhedron::Face& face : surface->faces)
    for (std::uint32_t k = 1; k + 1 < face.count; ++k)
      for (std::uint32_t corner : {0u, k, k + 1}) {
        const Vec3 v =
            part.pose.transform(surface->vertices[surface->face_vertices[face.first + corner]]);
        out->push_back({v.x(), v.y(), v.z()});
      }
}

// A hull's vertices into `out` (emptied first; nothing for another shape), for a sample to view.
void hull_vertices(const Shape& shape, std::vector<Point>* out) {
  out->clear();
  if (shape.type() == ShapeType::kHull)
    for (const Vec3& v : shape.polyhedron()->vertices)
      out->push_back({v.x(), v.y(), v.z()});
}

// A compound's part as the bodies topic gives it: its shape's sizes, a hull's vertices (in
// `vertices`, which the sample views) and its pose in the body's frame.
BodyPartSample part_sample(const Compound::Part& part, std::vector<Point>* vertices) {
  BodyPartSample sample{};
  const Shape& shape = part.shape;
  sample.shape = static_cast<std::uint8_t>(shape.type());
  sample.pose.position = {part.pose.position.x(), part.pose.position.y(), part.pose.position.z()};
  const Quat& q = part.pose.orientation;
  sample.pose.orientation = {q.x(), q.y(), q.z(), q.w()};
  sample.radius = shape.radius();
  sample.half_height = shape.half_height();
  for (int k = 0; k < 3; ++k)
    sample.half_extents[k] = shape.half_extents()[k];
  hull_vertices(shape, vertices);
  sample.hull_vertices = view<dds_sequence_geometry_msgs_msg_dds__Point_>(*vertices);
  return sample;
}

}  // namespace

struct DdsPublisher::Writers {
  dds_entity_t participant = 0;
  dds_entity_t poses = 0, ids = 0, contacts = 0, stats = 0, bodies = 0;
  dds_entity_t tf = 0, clock = 0, markers = 0, joint_states = 0;  // ROS 2's own types
  // Each joint's name ("joint_<id>") by the order of the frame's joints, kept while it is the
  // same (names are strings: not remade each step).
  std::vector<std::uint64_t> joint_ids;
  std::vector<std::string> joint_names;
  std::vector<char*> joint_name_pointers;
  // What each body looks like to ROS 2, made when the catalogue changes: its frame's name, and
  // its marker (type, scale, colour, the triangles of a hull), the pose filled in per step.
  struct RosLook {
    std::string frame;
    Marker marker;
    std::vector<Point> triangles;
    bool ground = false;  // a half-space: its slab sits below the body's origin
  };
  std::unordered_map<std::uint64_t, RosLook> ros_looks;
  std::vector<std::uint64_t> deleted_markers;  // bodies gone since the last markers went out
  std::vector<Transform> transform_buffer;
  std::vector<Marker> marker_buffer;
  // Buffers kept from step to step, so a steady world publishes without allocating.
  std::vector<Pose> pose_buffer;
  std::vector<std::uint64_t> id_buffer;
  std::vector<Point> contact_points;
  std::vector<Vector3> contact_normals;
  std::vector<std::uint64_t> contact_a, contact_b;
  std::vector<double> contact_depths, contact_impulses;

  ~Writers() {
    if (participant > 0) dds_delete(participant);  // and every writer and topic inside it
  }
};

Result<std::unique_ptr<DdsPublisher>> DdsPublisher::start(WorldHost& host, DdsOptions options) {
  if (!(options.rate >= 0) || !std::isfinite(options.rate))
    return Status::error("dds-rate: must be finite and >= 0");
  auto writers = std::make_unique<Writers>();
  writers->participant = dds_create_participant(options.domain, nullptr, nullptr);
  if (writers->participant < 0)
    return Status::error(dds_error("dds: cannot join the domain", writers->participant));

  dds_qos_t* states = tumble_states_qos();
  dds_qos_t* catalogue = tumble_catalogue_qos(DDS_MSECS(100));

  Status failed = Status::ok();
  auto writer = [&](const dds_topic_descriptor_t* type, const char* name, const dds_qos_t* qos) {
    if (!failed) return dds_entity_t{0};
    const dds_entity_t topic = dds_create_topic(writers->participant, type, name, qos, nullptr);
    if (topic < 0) {
      failed = Status::error(dds_error((std::string("dds: topic ") + name).c_str(), topic));
      return topic;
    }
    const dds_entity_t w = dds_create_writer(writers->participant, topic, qos, nullptr);
    if (w < 0) failed = Status::error(dds_error((std::string("dds: writer ") + name).c_str(), w));
    return w;
  };
  writers->poses = writer(&geometry_msgs_msg_dds__PoseArray__desc, "rt/tumble/poses", states);
  writers->ids = writer(&tumble_msgs_msg_dds__BodyIds__desc, "rt/tumble/pose_ids", states);
  writers->contacts = writer(&tumble_msgs_msg_dds__Contacts__desc, "rt/tumble/contacts", states);
  writers->stats = writer(&tumble_msgs_msg_dds__StepStats__desc, "rt/tumble/stats", states);
  writers->bodies = writer(&tumble_msgs_msg_dds__Body__desc, "rt/tumble/bodies", catalogue);
  dds_qos_t* ros2 = tumble_ros2_default_qos(DDS_MSECS(10));
  writers->tf = writer(&tf2_msgs_msg_dds__TFMessage__desc, "rt/tf", ros2);
  writers->clock = writer(&rosgraph_msgs_msg_dds__Clock__desc, "rt/clock", ros2);
  writers->markers =
      writer(&visualization_msgs_msg_dds__MarkerArray__desc, "rt/tumble/markers", ros2);
  writers->joint_states = writer(&sensor_msgs_msg_dds__JointState__desc, "rt/joint_states", ros2);
  dds_delete_qos(ros2);
  dds_delete_qos(states);
  dds_delete_qos(catalogue);
  if (!failed) return failed;
  return std::unique_ptr<DdsPublisher>(new DdsPublisher(host, options, std::move(writers)));
}

DdsPublisher::DdsPublisher(WorldHost& host, DdsOptions options, std::unique_ptr<Writers> writers)
    : host_(host), options_(options), writers_(std::move(writers)), mailbox_(host.subscribe()) {
  thread_ = std::thread([this] { run(); });
}

DdsPublisher::~DdsPublisher() {
  stopping_ = true;
  mailbox_->close();
  thread_.join();
  host_.unsubscribe(mailbox_);
}

void DdsPublisher::run() {
  using Clock = std::chrono::steady_clock;
  const auto interval = std::chrono::duration<double>(options_.rate > 0 ? 1 / options_.rate : 0);
  auto last = Clock::time_point{};
  while (!stopping_) {
    auto delivery = mailbox_->take(std::chrono::milliseconds(100));
    if (!delivery) continue;
    skipped_ += delivery->dropped;
    // The catalogue goes out whatever the rate: a subscriber must know every body.
    if (delivery->frame->catalogue != catalogue_) publish_catalogue(*delivery->frame);
    const auto now = Clock::now();
    if (now - last < interval) {
      ++skipped_;
      continue;
    }
    last = now;
    publish(*delivery->frame);
    ++published_;
  }
}

void DdsPublisher::publish(const FrameData& frame) {
  Writers& w = *writers_;
  const std::size_t n = frame.ids.size();
  w.pose_buffer.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    Pose& p = w.pose_buffer[i];
    p.position = {frame.positions[3 * i], frame.positions[3 * i + 1], frame.positions[3 * i + 2]};
    // Ours are stored w x y z; ROS 2's Quaternion is x y z w.
    p.orientation = {frame.orientations[4 * i + 1], frame.orientations[4 * i + 2],
                     frame.orientations[4 * i + 3], frame.orientations[4 * i]};
  }
  w.id_buffer.assign(frame.ids.begin(), frame.ids.end());
  const auto header = header_at(frame.time);

  PoseArray poses{header, view<dds_sequence_geometry_msgs_msg_dds__Pose_>(w.pose_buffer)};
  PoseIds ids{header, frame.step, frame.stepped_at_unix_ns, view<dds_sequence_uint64>(w.id_buffer)};
  // The ids first: a subscriber that has a step's poses can then find their ids.
  dds_write(w.ids, &ids);
  dds_write(w.poses, &poses);

  w.contact_points.clear();
  w.contact_normals.clear();
  w.contact_a.clear();
  w.contact_b.clear();
  w.contact_depths.clear();
  w.contact_impulses.clear();
  for (const ContactTable* table : frame.contact_tables()) {
    for (std::size_t c = 0; c < table->size(); ++c) {
      w.contact_points.push_back(
          {table->points[3 * c], table->points[3 * c + 1], table->points[3 * c + 2]});
      w.contact_normals.push_back(
          {table->normals[3 * c], table->normals[3 * c + 1], table->normals[3 * c + 2]});
    }
    w.contact_a.insert(w.contact_a.end(), table->a.begin(), table->a.end());
    w.contact_b.insert(w.contact_b.end(), table->b.begin(), table->b.end());
    w.contact_depths.insert(w.contact_depths.end(), table->depths.begin(), table->depths.end());
    w.contact_impulses.insert(w.contact_impulses.end(), table->impulses.begin(),
                              table->impulses.end());
  }
  Contacts contacts{header,
                    frame.step,
                    view<dds_sequence_uint64>(w.contact_a),
                    view<dds_sequence_uint64>(w.contact_b),
                    view<dds_sequence_geometry_msgs_msg_dds__Point_>(w.contact_points),
                    view<dds_sequence_geometry_msgs_msg_dds__Vector3_>(w.contact_normals),
                    view<dds_sequence_double>(w.contact_depths),
                    view<dds_sequence_double>(w.contact_impulses)};
  dds_write(w.contacts, &contacts);

  const StepStats& s = frame.stats;
  Stats stats{header,
              frame.step,
              static_cast<std::uint32_t>(n),
              s.pairs,
              s.manifolds,
              s.contact_points,
              s.islands,
              s.sleeping_bodies,
              s.velocity_iterations,
              s.lemke_pivots,
              s.residual,
              s.max_penetration,
              s.non_finite_bodies,
              s.slowed_bodies,
              s.bodies_at_edge,
              s.time.total};
  dds_write(w.stats, &stats);
  publish_ros2(frame, header);
}

void DdsPublisher::publish_ros2(const FrameData& frame, const std_msgs_msg_dds__Header_& header) {
  Writers& w = *writers_;
  Clock clock{header.stamp};
  dds_write(w.clock, &clock);
  publish_joint_states(frame, header);

  // /tf and the markers carry the bodies changed since the previous sample: tf buffers and RViz
  // keep the last transform and marker of each body, so a world of sleeping bodies costs them
  // nothing a step. Every body goes out on the first sample, after the world was replaced, and
  // once a second (well within tf's ten-second buffer, for listeners that join late).
  const auto now = std::chrono::steady_clock::now();
  const bool full =
      frame.epoch != ros_sent_epoch_ || now - ros_last_full_ >= std::chrono::seconds(1);
  if (full) ros_last_full_ = now;
  const std::uint64_t since = full ? 0 : ros_sent_tick_;
  ros_sent_tick_ = frame.change_clock;
  ros_sent_epoch_ = frame.epoch;
  const std::size_t n = frame.ids.size();
  w.transform_buffer.clear();
  w.marker_buffer.clear();
  for (std::size_t i = 0; i < n; ++i) {
    if (since > 0 && i < frame.changed_at.size() && frame.changed_at[i] <= since) continue;
    const auto look = w.ros_looks.find(frame.ids[i]);
    if (look == w.ros_looks.end()) continue;  // not in the catalogue published: next step
    const geometry_msgs_msg_dds__Vector3_ at{frame.positions[3 * i], frame.positions[3 * i + 1],
                                             frame.positions[3 * i + 2]};
    // Ours are stored w x y z; ROS 2's Quaternion is x y z w.
    const geometry_msgs_msg_dds__Quaternion_ turn{
        frame.orientations[4 * i + 1], frame.orientations[4 * i + 2], frame.orientations[4 * i + 3],
        frame.orientations[4 * i]};
    Transform& t = w.transform_buffer.emplace_back();
    t.header = header;
    t.child_frame_id = look->second.frame.data();
    t.transform = {at, turn};
    Marker marker = look->second.marker;
    marker.header = header;
    marker.texture.header = header;
    marker.pose = {{at.x, at.y, at.z}, turn};
    if (look->second.ground) {
      // The slab's top at the ground's surface: its centre half its thickness below, along the
      // ground's normal (its frame's z).
      const Quat q(frame.orientations[4 * i], frame.orientations[4 * i + 1],
                   frame.orientations[4 * i + 2], frame.orientations[4 * i + 3]);
      const Vec3 centre = Vec3(at.x, at.y, at.z) - q * Vec3(0, 0, kGroundThickness / 2);
      marker.pose.position = {centre.x(), centre.y(), centre.z()};
    }
    w.marker_buffer.push_back(marker);
  }
  TfMessage tf{view<dds_sequence_geometry_msgs_msg_dds__TransformStamped_>(w.transform_buffer)};
  dds_write(w.tf, &tf);
  for (std::uint64_t gone : w.deleted_markers) {
    Marker marker = empty_marker(header);
    marker.id = marker_id(gone);
    marker.action = kDelete;
    w.marker_buffer.push_back(marker);
  }
  w.deleted_markers.clear();
  MarkerArray markers{view<dds_sequence_visualization_msgs_msg_dds__Marker_>(w.marker_buffer)};
  dds_write(w.markers, &markers);
}

void DdsPublisher::describe_for_ros2(const Catalogue& now) {
  Writers& w = *writers_;
  for (auto it = w.ros_looks.begin(); it != w.ros_looks.end();) {
    if (now.contains(it->first)) {
      ++it;
      continue;
    }
    w.deleted_markers.push_back(it->first);
    it = w.ros_looks.erase(it);
  }
  for (const auto& [id, look] : now) {
    if (w.ros_looks.contains(id)) continue;
    Writers::RosLook& ros = w.ros_looks[id];
    ros.frame = "body_" + std::to_string(id);
    Marker& marker = ros.marker = empty_marker({});
    marker.id = marker_id(id);
    marker.action = kAdd;
    marker.color = colour_of(look);
    const Shape& shape = look.shape;
    switch (shape.type()) {
      case ShapeType::kSphere:
        marker.type = kSphere;
        marker.scale = {2 * shape.radius(), 2 * shape.radius(), 2 * shape.radius()};
        break;
      case ShapeType::kCapsule:  // its length, ends included, as a cylinder
        marker.type = kCylinder;
        marker.scale = {2 * shape.radius(), 2 * shape.radius(),
                        2 * (shape.half_height() + shape.radius())};
        break;
      case ShapeType::kBox:
        marker.type = kCube;
        marker.scale = {2 * shape.half_extents().x(), 2 * shape.half_extents().y(),
                        2 * shape.half_extents().z()};
        break;
      case ShapeType::kHalfSpace:
        ros.ground = true;
        marker.type = kCube;
        marker.scale = {kGroundWidth, kGroundWidth, kGroundThickness};
        break;
      case ShapeType::kHull: {
        // Each face's loop as a fan of triangles, in the body's frame.
        marker.type = kTriangleList;
        marker.scale = {1, 1, 1};
        const ConvexPolyhedron& hull = *shape.polyhedron();
        for (const ConvexPolyhedron::Face& face : hull.faces)
          for (std::uint32_t k = 1; k + 1 < face.count; ++k)
            for (std::uint32_t corner : {0u, k, k + 1}) {
              const Vec3& v = hull.vertices[hull.face_vertices[face.first + corner]];
              ros.triangles.push_back({v.x(), v.y(), v.z()});
            }
        break;
      }
      case ShapeType::kHeightField: {
        // Its surface's triangles, every stride-th sample where it has more than a marker
        // should carry (kMaxMarkerTriangles).
        marker.type = kTriangleList;
        marker.scale = {1, 1, 1};
        const HeightField& field = *shape.height_field();
        std::uint32_t stride = 1;
        while (2.0 * (field.cells_x() / stride) * (field.cells_y() / stride) > kMaxMarkerTriangles)
          ++stride;
        const auto corner = [&](std::uint32_t i, std::uint32_t j) {
          const Vec3 p = field.sample(std::min(i, field.cells_x()), std::min(j, field.cells_y()));
          ros.triangles.push_back({p.x(), p.y(), p.z()});
        };
        for (std::uint32_t j = 0; j < field.cells_y(); j += stride)
          for (std::uint32_t i = 0; i < field.cells_x(); i += stride) {
            const std::uint32_t i1 = i + stride, j1 = j + stride;
            corner(i, j), corner(i1, j), corner(i1, j1);
            corner(i, j), corner(i1, j1), corner(i, j1);
          }
        break;
      }
      case ShapeType::kCompound: {
        marker.type = kTriangleList;
        marker.scale = {1, 1, 1};
        for (const Compound::Part& part : shape.compound()->parts())
          add_part_triangles(part, &ros.triangles);
        break;
      }
      case ShapeType::kMesh: {
        // Its triangles, the first kMaxMarkerTriangles of a larger mesh.
        marker.type = kTriangleList;
        marker.scale = {1, 1, 1};
        const TriangleMesh& mesh = *shape.mesh();
        const auto count =
            std::min(mesh.triangle_count(), static_cast<std::size_t>(kMaxMarkerTriangles));
        for (std::size_t t = 0; t < count; ++t)
          for (const Vec3& p : mesh.triangle(t))
            ros.triangles.push_back({p.x(), p.y(), p.z()});
        break;
      }
    }
  }
  // The points' buffers are final now (the map does not move its values).
  for (auto& [id, ros] : w.ros_looks)
    ros.marker.points = view<dds_sequence_geometry_msgs_msg_dds__Point_>(ros.triangles);
}

void DdsPublisher::publish_catalogue(const FrameData& frame) {
  Writers& w = *writers_;
  const Catalogue& now = *frame.catalogue;
  std::vector<Point> vertices;
  std::vector<BodyPartSample> parts;
  std::vector<std::vector<Point>> part_vertices;  // each hull part's, viewed by its sample
  BodySample sample{};
  for (auto it = described_.begin(); it != described_.end();) {
    if (now.contains(it->first)) {
      ++it;
      continue;
    }
    sample.instance = it->second;  // only the key matters to a dispose
    sample.id = it->first;
    dds_dispose(w.bodies, &sample);
    dds_unregister_instance(w.bodies, &sample);
    free_instances_.push_back(it->second);
    std::push_heap(free_instances_.begin(), free_instances_.end(), std::greater<>());
    it = described_.erase(it);
  }
  for (const auto& [id, look] : now) {
    if (described_.contains(id)) continue;  // ids are never reused: a known id is the same body
    const Shape& shape = look.shape;
    sample = BodySample{};
    if (free_instances_.empty()) {
      sample.instance = next_instance_++;
    } else {
      std::pop_heap(free_instances_.begin(), free_instances_.end(), std::greater<>());
      sample.instance = free_instances_.back();
      free_instances_.pop_back();
    }
    sample.id = id;
    sample.shape = static_cast<std::uint8_t>(shape.type());
    sample.is_static = look.type == BodyType::kStatic;
    sample.radius = shape.radius();
    sample.half_height = shape.half_height();
    for (int k = 0; k < 3; ++k)
      sample.half_extents[k] = shape.half_extents()[k];
    hull_vertices(shape, &vertices);
    sample.hull_vertices = view<dds_sequence_geometry_msgs_msg_dds__Point_>(vertices);
    parts.clear();
    if (shape.type() == ShapeType::kCompound) {
      const std::span<const Compound::Part> compound = shape.compound()->parts();
      if (part_vertices.size() < compound.size()) part_vertices.resize(compound.size());
      for (std::size_t i = 0; i < compound.size(); ++i)
        parts.push_back(part_sample(compound[i], &part_vertices[i]));
    }
    sample.parts = view<dds_sequence_tumble_msgs_msg_dds__BodyPart_>(parts);
    sample.mass = look.mass;
    sample.color = look.colour;
    dds_write(w.bodies, &sample);
    described_.emplace(id, sample.instance);
  }
  describe_for_ros2(now);
  catalogue_ = frame.catalogue;
}

void DdsPublisher::publish_joint_states(const FrameData& frame,
                                        const std_msgs_msg_dds__Header_& header) {
  // sensor_msgs/JointState, as robot_state_publisher and RViz read it: a world without joints
  // sends nothing.
  const JointTable& joints = frame.joints;
  if (joints.size() == 0) return;
  Writers& w = *writers_;
  if (w.joint_ids != joints.ids) {
    w.joint_ids = joints.ids;
    w.joint_names.clear();
    for (std::uint64_t id : joints.ids)
      w.joint_names.push_back("joint_" + std::to_string(id));
    w.joint_name_pointers.clear();
    for (std::string& name : w.joint_names)
      w.joint_name_pointers.push_back(name.data());
  }
  // DDS reads the buffers on write and never writes them: the frame's own arrays serve.
  auto doubles = [](const std::vector<double>& values) {
    return view<dds_sequence_double>(const_cast<std::vector<double>&>(values));
  };
  JointStates states{header, view<dds_sequence_string>(w.joint_name_pointers),
                     doubles(joints.positions), doubles(joints.speeds), doubles(joints.efforts)};
  dds_write(w.joint_states, &states);
}

}  // namespace tumble::server
