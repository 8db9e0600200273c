// tumble-dds-echo: reads what tumble-server --dds publishes and prints it as JSON lines, one
// sample a line, so other programs (and tests) can read Tumble's states without gRPC. It is also
// the smallest example of a DDS program reading them: Cyclone DDS's C API, the types that idlc
// generates from proto/dds/tumble_states.idl and the topics' QoS (proto/dds/tumble_qos.h),
// nothing of Tumble's.
#include <dds/dds.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <unordered_map>
#include <vector>

#include "tumble/command_line.h"
#include "tumble_qos.h"
#include "tumble_states.h"

namespace {

using Json = nlohmann::json;

Json stamp(const std_msgs_msg_dds__Header_& header) {
  return header.stamp.sec + header.stamp.nanosec * 1e-9;
}

template <class Sequence>
Json numbers(const Sequence& s) {
  Json out = Json::array();
  for (std::uint32_t i = 0; i < s._length; ++i)
    out.push_back(s._buffer[i]);
  return out;
}

template <class Sequence>
Json points(const Sequence& s) {
  Json out = Json::array();
  for (std::uint32_t i = 0; i < s._length; ++i)
    out.push_back({s._buffer[i].x, s._buffer[i].y, s._buffer[i].z});
  return out;
}

Json poses_json(const geometry_msgs_msg_dds__PoseArray_& m) {
  Json poses = Json::array();
  for (std::uint32_t i = 0; i < m.poses._length; ++i) {
    const auto& p = m.poses._buffer[i];
    poses.push_back({{"p", {p.position.x, p.position.y, p.position.z}},
                     {"q", {p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z}}});
  }
  return {{"topic", "poses"}, {"time", stamp(m.header)}, {"poses", poses}};
}

Json ids_json(const tumble_msgs_msg_dds__BodyIds_& m) {
  return {
      {"topic", "pose_ids"}, {"step", m.step}, {"time", stamp(m.header)}, {"ids", numbers(m.ids)}};
}

Json contacts_json(const tumble_msgs_msg_dds__Contacts_& m) {
  return {{"topic", "contacts"},
          {"step", m.step},
          {"time", stamp(m.header)},
          {"body_a", numbers(m.body_a)},
          {"body_b", numbers(m.body_b)},
          {"points", points(m.points)},
          {"normals", points(m.normals)},
          {"depths", numbers(m.depths)},
          {"impulses", numbers(m.impulses)}};
}

Json stats_json(const tumble_msgs_msg_dds__StepStats_& m) {
  return {{"topic", "stats"},
          {"step", m.step},
          {"time", stamp(m.header)},
          {"bodies", m.bodies},
          {"pairs", m.pairs},
          {"contact_points", m.contact_points},
          {"islands", m.islands},
          {"sleeping_bodies", m.sleeping_bodies},
          {"max_penetration", m.max_penetration},
          {"step_seconds", m.step_seconds}};
}

Json body_json(const tumble_msgs_msg_dds__Body_& m) {
  const char* shapes[] = {"sphere", "capsule",     "box",  "hull",
                          "plane",  "heightfield", "mesh", "compound"};
  Json out = {{"topic", "bodies"},      {"id", m.id},
              {"instance", m.instance}, {"shape", m.shape < 8 ? shapes[m.shape] : "unknown"},
              {"static", m.is_static},  {"mass", m.mass},
              {"color", m.color}};
  if (m.shape == 0 || m.shape == 1) out["radius"] = m.radius;
  if (m.shape == 1) out["half_height"] = m.half_height;
  if (m.shape == 2) out["half_extents"] = {m.half_extents[0], m.half_extents[1], m.half_extents[2]};
  if (m.shape == 3) out["hull_vertices"] = points(m.hull_vertices);
  if (m.shape == 7) {
    Json parts = Json::array();
    for (std::uint32_t i = 0; i < m.parts._length; ++i) {
      const tumble_msgs_msg_dds__BodyPart_& part = m.parts._buffer[i];
      const auto& p = part.pose.position;
      const auto& q = part.pose.orientation;
      Json entry = {{"shape", part.shape < 4 ? shapes[part.shape] : "unknown"},
                    {"p", {p.x, p.y, p.z}},
                    {"q", {q.w, q.x, q.y, q.z}}};
      if (part.shape == 0 || part.shape == 1) entry["radius"] = part.radius;
      if (part.shape == 1) entry["half_height"] = part.half_height;
      if (part.shape == 2)
        entry["half_extents"] = {part.half_extents[0], part.half_extents[1], part.half_extents[2]};
      if (part.shape == 3) entry["hull_vertices"] = points(part.hull_vertices);
      parts.push_back(entry);
    }
    out["parts"] = parts;
  }
  return out;
}

struct Subscription {
  std::string name;
  dds_entity_t reader = 0;
  Json (*to_json)(const void* sample);
};

template <class T, Json (*Convert)(const T&)>
Json convert(const void* sample) {
  return Convert(*static_cast<const T*>(sample));
}

}  // namespace

Json clock_json(const rosgraph_msgs_msg_dds__Clock_& m) {
  return {{"topic", "clock"}, {"time", m.clock.sec + m.clock.nanosec * 1e-9}};
}

Json tf_json(const tf2_msgs_msg_dds__TFMessage_& m) {
  Json transforms = Json::array();
  double time = 0;
  for (std::uint32_t i = 0; i < m.transforms._length; ++i) {
    const auto& t = m.transforms._buffer[i];
    time = stamp(t.header);
    const auto& v = t.transform.translation;
    const auto& q = t.transform.rotation;
    transforms.push_back({{"parent", t.header.frame_id},
                          {"child", t.child_frame_id},
                          {"p", {v.x, v.y, v.z}},
                          {"q", {q.w, q.x, q.y, q.z}}});
  }
  return {{"topic", "tf"}, {"time", time}, {"transforms", transforms}};
}

Json joint_states_json(const sensor_msgs_msg_dds__JointState_& m) {
  Json names = Json::array();
  for (std::uint32_t i = 0; i < m.name._length; ++i)
    names.push_back(m.name._buffer[i]);
  auto doubles = [](const dds_sequence_double& values) {
    return std::vector<double>(values._buffer, values._buffer + values._length);
  };
  return {{"topic", "joint_states"},
          {"time", stamp(m.header)},
          {"name", names},
          {"position", doubles(m.position)},
          {"velocity", doubles(m.velocity)},
          {"effort", doubles(m.effort)}};
}

int main(int argc, char** argv) {
  CLI::App app{"Prints what tumble-server --dds publishes, as JSON lines."};
  tumble::cli::keep_conventions(app, "tumble-dds-echo");
  std::uint32_t domain = 0;
  std::vector<std::string> topics = {"poses", "pose_ids", "contacts", "stats", "bodies"};
  long count = 0;
  double timeout = 0;
  app.add_option("--domain", domain, "the DDS domain")->envname("TUMBLE_DDS_DOMAIN");
  app.add_option("--topics", topics,
                 "which of poses, pose_ids, contacts, stats, bodies, and of ROS 2's clock, tf and "
                 "joint_states")
      ->delimiter(',')
      ->check(CLI::IsMember(
          {"poses", "pose_ids", "contacts", "stats", "bodies", "clock", "tf", "joint_states"}));
  app.add_option("--count", count, "stop after this many samples (0: never)")
      ->check(tumble::cli::non_negative);
  app.add_option("--timeout", timeout,
                 "stop after this many seconds (0: never); exit 1 if --count was not reached")
      ->check(tumble::cli::non_negative);
  if (const int exit_status = tumble::cli::parse(app, argc, argv); exit_status >= 0)
    return exit_status;

  const dds_entity_t participant = dds_create_participant(domain, nullptr, nullptr);
  if (participant < 0) {
    std::fprintf(stderr, "tumble-dds-echo: cannot join domain %u: %s\n", domain,
                 dds_strretcode(participant));
    return 1;
  }
  dds_qos_t* states = tumble_states_qos();
  dds_qos_t* catalogue = tumble_catalogue_qos(DDS_SECS(1));
  dds_qos_t* ros2 = tumble_ros2_default_qos(DDS_SECS(1));

  const std::set<std::string> wanted(topics.begin(), topics.end());
  const dds_entity_t waitset = dds_create_waitset(participant);
  std::vector<Subscription> subscriptions;
  auto subscribe = [&](const char* name, const char* topic_name, const dds_topic_descriptor_t* type,
                       const dds_qos_t* qos, Json (*to_json)(const void*)) {
    if (!wanted.contains(name)) return true;
    const dds_entity_t topic = dds_create_topic(participant, type, topic_name, qos, nullptr);
    const dds_entity_t reader =
        topic < 0 ? topic : dds_create_reader(participant, topic, qos, nullptr);
    if (reader < 0) {
      std::fprintf(stderr, "tumble-dds-echo: %s: %s\n", topic_name, dds_strretcode(reader));
      return false;
    }
    dds_set_status_mask(reader, DDS_DATA_AVAILABLE_STATUS);
    dds_waitset_attach(waitset, reader, static_cast<dds_attach_t>(subscriptions.size()));
    subscriptions.push_back({name, reader, to_json});
    return true;
  };
  using geometry_msgs_msg_dds__PoseArray = geometry_msgs_msg_dds__PoseArray_;
  const bool ok =
      subscribe("poses", "rt/tumble/poses", &geometry_msgs_msg_dds__PoseArray__desc, states,
                convert<geometry_msgs_msg_dds__PoseArray, poses_json>) &&
      subscribe("pose_ids", "rt/tumble/pose_ids", &tumble_msgs_msg_dds__BodyIds__desc, states,
                convert<tumble_msgs_msg_dds__BodyIds_, ids_json>) &&
      subscribe("contacts", "rt/tumble/contacts", &tumble_msgs_msg_dds__Contacts__desc, states,
                convert<tumble_msgs_msg_dds__Contacts_, contacts_json>) &&
      subscribe("stats", "rt/tumble/stats", &tumble_msgs_msg_dds__StepStats__desc, states,
                convert<tumble_msgs_msg_dds__StepStats_, stats_json>) &&
      subscribe("bodies", "rt/tumble/bodies", &tumble_msgs_msg_dds__Body__desc, catalogue,
                convert<tumble_msgs_msg_dds__Body_, body_json>) &&
      subscribe("clock", "rt/clock", &rosgraph_msgs_msg_dds__Clock__desc, ros2,
                convert<rosgraph_msgs_msg_dds__Clock_, clock_json>) &&
      subscribe("tf", "rt/tf", &tf2_msgs_msg_dds__TFMessage__desc, ros2,
                convert<tf2_msgs_msg_dds__TFMessage_, tf_json>) &&
      subscribe("joint_states", "rt/joint_states", &sensor_msgs_msg_dds__JointState__desc, ros2,
                convert<sensor_msgs_msg_dds__JointState_, joint_states_json>);
  dds_delete_qos(states);
  dds_delete_qos(catalogue);
  dds_delete_qos(ros2);
  if (!ok) {
    dds_delete(participant);
    return 1;
  }

  const auto start = std::chrono::steady_clock::now();
  long printed = 0;
  constexpr double kSilenceWarning = 5, kForever = 1e9;
  bool told_of_silence = false;
  std::unordered_map<std::uint32_t, std::uint64_t> body_at;  // the body each instance holds
  while (count == 0 || printed < count) {
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (timeout > 0 && elapsed >= timeout) break;
    // Silence is the usual first trouble (no server with --dds, another domain, a firewall):
    // say so once, then keep waiting.
    if (!told_of_silence && printed == 0 && elapsed >= kSilenceWarning) {
      std::fprintf(stderr,
                   "tumble-dds-echo: nothing received on domain %u in %.0f s; is a tumble-server "
                   "running with --dds on this domain and network? (still waiting)\n",
                   domain, kSilenceWarning);
      told_of_silence = true;
    }
    double wait_seconds = timeout > 0 ? timeout - elapsed : kForever;
    if (!told_of_silence) wait_seconds = std::min(wait_seconds, kSilenceWarning - elapsed);
    const dds_duration_t wait = wait_seconds >= kForever
                                    ? DDS_INFINITY
                                    : static_cast<dds_duration_t>(DDS_SECS(1) * wait_seconds);
    dds_attach_t triggered[8];
    const dds_return_t n = dds_waitset_wait(waitset, triggered, 8, wait);
    for (dds_return_t t = 0; t < n; ++t) {
      const Subscription& s = subscriptions[static_cast<std::size_t>(triggered[t])];
      void* samples[16] = {};
      dds_sample_info_t infos[16];
      const dds_return_t taken = dds_take(s.reader, samples, infos, 16, 16);
      for (dds_return_t i = 0; i < taken && (count == 0 || printed < count); ++i) {
        std::vector<Json> lines;
        if (infos[i].valid_data) {
          if (s.name == "bodies") {
            // An instance that held another body: that body is gone (its dispose may have been
            // overwritten before it was read).
            const auto& body = *static_cast<const tumble_msgs_msg_dds__Body_*>(samples[i]);
            const auto held = body_at.find(body.instance);
            if (held != body_at.end() && held->second != body.id)
              lines.push_back({{"topic", "bodies"}, {"id", held->second}, {"removed", true}});
            body_at[body.instance] = body.id;
          }
          lines.push_back(s.to_json(samples[i]));
        } else if (infos[i].instance_state != DDS_IST_ALIVE && s.name == "bodies") {
          tumble_msgs_msg_dds__Body_ key{};
          dds_instance_get_key(s.reader, infos[i].instance_handle, &key);
          const auto held = body_at.find(key.instance);
          if (held == body_at.end()) continue;  // a body this reader never saw
          lines.push_back({{"topic", "bodies"}, {"id", held->second}, {"removed", true}});
          body_at.erase(held);
        }
        for (const Json& line : lines) {
          std::printf("%s\n", line.dump().c_str());
          ++printed;
        }
      }
      std::fflush(stdout);
      if (taken > 0) dds_return_loan(s.reader, samples, taken);
    }
  }
  dds_delete(participant);
  return count > 0 && printed < count ? 1 : 0;
}
