#include "dds_publisher.h"

#include <dds/dds.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "tumble_qos.h"
#include "tumble_states.h"

namespace tumble::server {
namespace {

constexpr char kFrameId[] = "world";

using PoseArray = geometry_msgs_msg_dds__PoseArray_;
using Pose = geometry_msgs_msg_dds__Pose_;
using Point = geometry_msgs_msg_dds__Point_;
using Vector3 = geometry_msgs_msg_dds__Vector3_;
using PoseIds = tumble_msg_dds__BodyIds_;
using Contacts = tumble_msg_dds__Contacts_;
using Stats = tumble_msg_dds__StepStats_;
using BodySample = tumble_msg_dds__Body_;

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

std::string dds_error(const char* what, dds_return_t code) {
  return std::string(what) + ": " + dds_strretcode(code);
}

}  // namespace

struct DdsPublisher::Writers {
  dds_entity_t participant = 0;
  dds_entity_t poses = 0, ids = 0, contacts = 0, stats = 0, bodies = 0;
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
  writers->ids = writer(&tumble_msg_dds__BodyIds__desc, "rt/tumble/pose_ids", states);
  writers->contacts = writer(&tumble_msg_dds__Contacts__desc, "rt/tumble/contacts", states);
  writers->stats = writer(&tumble_msg_dds__StepStats__desc, "rt/tumble/stats", states);
  writers->bodies = writer(&tumble_msg_dds__Body__desc, "rt/tumble/bodies", catalogue);
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

  const std::size_t points = frame.contact_a.size();
  w.contact_points.resize(points);
  w.contact_normals.resize(points);
  for (std::size_t c = 0; c < points; ++c) {
    w.contact_points[c] = {frame.contact_points[3 * c], frame.contact_points[3 * c + 1],
                           frame.contact_points[3 * c + 2]};
    w.contact_normals[c] = {frame.contact_normals[3 * c], frame.contact_normals[3 * c + 1],
                            frame.contact_normals[3 * c + 2]};
  }
  w.contact_a.assign(frame.contact_a.begin(), frame.contact_a.end());
  w.contact_b.assign(frame.contact_b.begin(), frame.contact_b.end());
  w.contact_depths.assign(frame.contact_depths.begin(), frame.contact_depths.end());
  w.contact_impulses.assign(frame.contact_impulses.begin(), frame.contact_impulses.end());
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
}

void DdsPublisher::publish_catalogue(const FrameData& frame) {
  Writers& w = *writers_;
  const Catalogue& now = *frame.catalogue;
  std::vector<Point> vertices;
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
    vertices.clear();
    if (shape.type() == ShapeType::kHull)
      for (const Vec3& v : shape.polyhedron()->vertices)
        vertices.push_back({v.x(), v.y(), v.z()});
    sample.hull_vertices = view<dds_sequence_geometry_msgs_msg_dds__Point_>(vertices);
    sample.mass = look.mass;
    sample.color = look.colour;
    dds_write(w.bodies, &sample);
    described_.emplace(id, sample.instance);
  }
  catalogue_ = frame.catalogue;
}

}  // namespace tumble::server
