// The server's DDS publishing, on loopback only: what tumble-dds-echo receives for a step equals
// the gRPC frame of the same step, bit for bit, and a subscriber that joins late still learns
// every live body (the catalogue is transient local) and none of the removed ones.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <set>
#include <thread>

#include "process_support.h"
#include "tumble/v1/world.grpc.pb.h"

namespace tumble::testing {
namespace {

using Json = nlohmann::json;
using namespace std::chrono_literals;

// Cyclone DDS on the loopback interface only, unicast discovery to 127.0.0.1.
constexpr char kLoopback[] =
    "<CycloneDDS><Domain><General><Interfaces><NetworkInterface name=\"lo\"/></Interfaces>"
    "<AllowMulticast>false</AllowMulticast></General><Discovery><ParticipantIndex>auto"
    "</ParticipantIndex><Peers><Peer address=\"127.0.0.1\"/></Peers></Discovery></Domain>"
    "</CycloneDDS>";

// A domain of this process's own, so that suites running side by side do not hear each other.
std::string own_domain() {
  return std::to_string(1 + getpid() % 200);
}

// Runs a subscriber (`program` on this test's domain, then `args`) in the background and collects
// the JSON lines it prints.
class Echo {
 public:
  explicit Echo(const std::string& args, const std::string& program = TUMBLE_DDS_ECHO_BINARY) {
    pipe_ = popen((program + " --domain " + own_domain() + " " + args).c_str(), "r");
    reader_ = std::thread([this] {
      char line[1 << 16];
      std::string partial;
      while (pipe_ != nullptr && fgets(line, sizeof line, pipe_) != nullptr) {
        partial += line;
        if (partial.empty() || partial.back() != '\n') continue;
        std::lock_guard lock(mutex_);
        lines_.push_back(Json::parse(partial));
        partial.clear();
      }
    });
  }
  // Waits for the echo to exit and returns what it printed.
  std::vector<Json> finish() {
    reader_.join();
    if (pipe_ != nullptr) pclose(pipe_);
    pipe_ = nullptr;
    std::lock_guard lock(mutex_);
    return lines_;
  }
  ~Echo() {
    if (reader_.joinable()) finish();
  }

 private:
  FILE* pipe_ = nullptr;
  std::thread reader_;
  std::mutex mutex_;
  std::vector<Json> lines_;
};

class DdsTest : public ::testing::Test {
 protected:
  void SetUp() override { setenv("CYCLONEDDS_URI", kLoopback, 1); }
  std::unique_ptr<v1::World::Stub> connect(const Server& server) {
    return v1::World::NewStub(
        grpc::CreateChannel(server.address, grpc::InsecureChannelCredentials()));
  }
};

// Steps a paused server `steps` times, one at a time, each step left time to arrive.
void step_one_at_a_time(v1::World::Stub& stub, int steps) {
  for (int k = 0; k < steps; ++k) {
    grpc::ClientContext context;
    v1::ControlRequest step;
    step.set_step(1);
    v1::ControlResponse response;
    EXPECT_TRUE(stub.Control(&context, step, &response).ok());
    std::this_thread::sleep_for(100ms);
  }
}

// What a subscriber printed while a paused server stepped 30 times, and the gRPC frame of every
// step, as a gRPC subscriber received them.
struct Received {
  std::vector<Json> lines;
  std::map<std::uint64_t, v1::Frame> frames;
  std::map<std::uint64_t, v1::BodyDescription> bodies;  // every body the frames described
};

Received thirty_steps(const std::string& subscriber_args, const std::string& program) {
  Server server;
  server.start({"--paused", "--dds", "--dds-domain", own_domain()});
  auto stub =
      v1::World::NewStub(grpc::CreateChannel(server.address, grpc::InsecureChannelCredentials()));

  // The gRPC frames of every step, as a subscriber receives them.
  std::mutex mutex;
  std::map<std::uint64_t, v1::Frame> frames;
  std::map<std::uint64_t, v1::BodyDescription> bodies;
  grpc::ClientContext stream_context;
  auto reader = stub->StreamFrames(&stream_context, {});
  std::thread streaming([&] {
    v1::Frame frame;
    while (reader->Read(&frame)) {
      std::lock_guard lock(mutex);
      for (const v1::BodyDescription& body : frame.added())
        bodies[body.id()] = body;
      frames[frame.step()] = frame;
    }
  });

  Echo echo(subscriber_args, program);
  std::this_thread::sleep_for(1500ms);  // discovery
  step_one_at_a_time(*stub, 30);
  Received received{echo.finish(), {}};
  stream_context.TryCancel();
  streaming.join();
  received.frames = std::move(frames);
  received.bodies = std::move(bodies);
  return received;
}

// How many steps `subscriber` received whole (ids and poses) and equal, bit for bit, to the gRPC
// frame of the same step.
int steps_equal_to_grpc_frames(const std::string& subscriber_args, const std::string& program) {
  Received received = thirty_steps(subscriber_args, program);
  const std::vector<Json>& lines = received.lines;
  std::map<std::uint64_t, v1::Frame>& frames = received.frames;
  std::mutex mutex;

  // Pair each step's ids with its poses (the same stamp), then compare with the gRPC frame.
  std::map<double, Json> ids_at;
  for (const Json& line : lines)
    if (line["topic"] == "pose_ids") ids_at[line["time"].get<double>()] = line;
  int equal = 0;
  for (const Json& line : lines) {
    if (line["topic"] != "poses" || !ids_at.contains(line["time"].get<double>())) continue;
    const Json& ids = ids_at[line["time"].get<double>()];
    const std::uint64_t step = ids["step"];
    std::lock_guard lock(mutex);
    if (step == 0 || !frames.contains(step)) continue;
    const v1::Frame& frame = frames[step];
    bool same = ids["ids"].size() == static_cast<std::size_t>(frame.ids_size()) &&
                line["poses"].size() == static_cast<std::size_t>(frame.ids_size());
    for (int i = 0; same && i < frame.ids_size(); ++i) {
      same = ids["ids"][i].get<std::uint64_t>() == frame.ids(i);
      const Json& pose = line["poses"][i];
      for (int k = 0; k < 3; ++k)
        same = same && pose["p"][k].get<double>() == frame.positions(3 * i + k);
      for (int k = 0; k < 4; ++k)
        same = same && pose["q"][k].get<double>() == frame.orientations(4 * i + k);
    }
    EXPECT_TRUE(same) << "step " << step << " differs from its gRPC frame";
    equal += same ? 1 : 0;
  }
  return equal;
}

TEST_F(DdsTest, PosesEqualTheGrpcFrameOfTheSameStep) {
  // Best effort on loopback loses little: most of the 30 steps must come through whole.
  EXPECT_GE(
      steps_equal_to_grpc_frames("--topics poses,pose_ids --timeout 6", TUMBLE_DDS_ECHO_BINARY),
      20);
}

#ifdef TUMBLE_FASTDDS_POSES_BINARY
// The proof that other tools can read us: eProsima Fast DDS, ROS 2's default DDS, built from the
// same IDL, receives the same poses.
TEST_F(DdsTest, AFastDdsSubscriberReceivesTheSamePoses) {
  EXPECT_GE(steps_equal_to_grpc_frames("--seconds 6", TUMBLE_FASTDDS_POSES_BINARY), 20);
}

// ROS 2's own topics, read by Fast DDS with ROS 2's default QoS (as RViz2 subscribes): /clock
// says each step's simulated time, /tf holds a transform from "world" to "body_<id>" equal to the
// step's gRPC frame for every body that changed since the sample before (every body at first), and
// /tumble/markers draws each body with the marker its shape calls for, at the same pose.
TEST_F(DdsTest, RosTopicsTfClockAndMarkersReachAFastDdsReader) {
  Received received = thirty_steps("--seconds 6 --ros2 1", TUMBLE_FASTDDS_POSES_BINARY);
  // The frames by simulated time (a header's stamp is it, to the nanosecond).
  std::map<long long, const v1::Frame*> at_time;
  const std::map<std::uint64_t, v1::BodyDescription>& bodies = received.bodies;
  for (const auto& [step, frame] : received.frames)
    at_time[std::llround(frame.time() * 1e6)] = &frame;
  ASSERT_EQ(bodies.size(), 51u);  // the default scene
  auto frame_at = [&](const Json& line) -> const v1::Frame* {
    const auto found = at_time.find(std::llround(line["time"].get<double>() * 1e6));
    return found == at_time.end() || found->second->step() == 0 ? nullptr : found->second;
  };
  int clocks = 0, transforms = 0, markers = 0;
  bool every_body_in_tf = false, moving_only_in_tf = false;
  for (const Json& line : received.lines) {
    const v1::Frame* frame = frame_at(line);
    if (frame == nullptr) continue;
    if (line["topic"] == "clock") ++clocks;
    // A body's row of the frame, by id (the samples list the bodies changed since the one before:
    // every body in the first, and once a second; the moving ones in between).
    std::map<std::uint64_t, int> row;
    for (int i = 0; i < frame->ids_size(); ++i)
      row[frame->ids(i)] = i;
    auto row_of = [&](const std::string& child) {
      const auto found = row.find(std::stoull(child.substr(std::string("body_").size())));
      return found == row.end() ? -1 : found->second;
    };
    if (line["topic"] == "tf") {
      const Json& list = line["transforms"];
      ASSERT_LE(list.size(), static_cast<std::size_t>(frame->ids_size()));
      every_body_in_tf |= list.size() == static_cast<std::size_t>(frame->ids_size());
      moving_only_in_tf |= list.size() == static_cast<std::size_t>(frame->ids_size()) - 1;
      int previous = -1;
      for (const Json& transform : list) {
        EXPECT_EQ(transform["parent"], "world");
        const int i = row_of(transform["child"].get<std::string>());
        ASSERT_GT(i, previous) << "in the frame's order, each once";
        previous = i;
        for (int k = 0; k < 3; ++k)
          EXPECT_EQ(transform["p"][k].get<double>(), frame->positions(3 * i + k));
        for (int k = 0; k < 4; ++k)
          EXPECT_EQ(transform["q"][k].get<double>(), frame->orientations(4 * i + k));
      }
      ++transforms;
    }
    if (line["topic"] == "markers") {
      const Json& list = line["markers"];
      ASSERT_LE(list.size(), static_cast<std::size_t>(frame->ids_size()));
      for (const Json& marker : list) {
        const int i = row_of("body_" + std::to_string(marker["id"].get<std::uint64_t>()));
        ASSERT_GE(i, 0);
        const v1::Shape& shape = bodies.at(frame->ids(i)).shape();
        EXPECT_EQ(marker["action"], 0);  // ADD
        const int expected_type = shape.has_sphere() ? 2 : shape.has_capsule() ? 3 : 1;
        EXPECT_EQ(marker["type"], expected_type) << shape.ShortDebugString();
        if (shape.has_box())
          for (int k = 0; k < 3; ++k)
            EXPECT_EQ(marker["scale"][k].get<double>(), k == 0   ? shape.box().size().x()
                                                        : k == 1 ? shape.box().size().y()
                                                                 : shape.box().size().z());
        if (shape.has_sphere())
          EXPECT_EQ(marker["scale"][0].get<double>(), 2 * shape.sphere().radius());
        if (!shape.has_plane())  // the ground's slab sits below its surface
          for (int k = 0; k < 3; ++k)
            EXPECT_EQ(marker["p"][k].get<double>(), frame->positions(3 * i + k));
        EXPECT_EQ(marker["color"][3].get<double>(), 1.0);
      }
      ++markers;
    }
  }
  // The first sample lists every body; later ones, within the second, the 50 falling ones
  // without the ground, which does not move.
  EXPECT_TRUE(every_body_in_tf);
  EXPECT_TRUE(moving_only_in_tf);
  // Reliable and keep last 10 on loopback: nearly every one of the 30 steps arrives.
  EXPECT_GE(clocks, 20);
  EXPECT_GE(transforms, 20);
  EXPECT_GE(markers, 20);
}
#endif

TEST_F(DdsTest, ALateSubscriberLearnsEveryLiveBodyAndNoRemovedOne) {
  Server server;
  server.start({"--dds", "--dds-domain", own_domain(), "--standard", "pyramid:3"});
  auto stub = connect(server);
  v1::SpawnBodiesRequest spawn;
  for (int i = 0; i < 3; ++i) {
    v1::BodySpec* ball = spawn.add_bodies();
    ball->mutable_shape()->mutable_sphere()->set_radius(0.3);
    ball->mutable_position()->set_z(5 + i);
  }
  v1::SpawnBodiesResponse spawned;
  {
    grpc::ClientContext context;
    ASSERT_TRUE(stub->SpawnBodies(&context, spawn, &spawned).ok());
  }
  {
    grpc::ClientContext context;
    v1::RemoveBodiesRequest remove;
    remove.add_ids(spawned.ids(1));
    v1::RemoveBodiesResponse removed;
    ASSERT_TRUE(stub->RemoveBodies(&context, remove, &removed).ok());
  }
  std::this_thread::sleep_for(500ms);  // the world has stepped on since

  std::set<std::uint64_t> live;
  {
    grpc::ClientContext context;
    v1::GetBodiesResponse bodies;
    ASSERT_TRUE(stub->GetBodies(&context, {}, &bodies).ok());
    for (const auto& state : bodies.states())
      live.insert(state.id());
  }
  ASSERT_EQ(live.size(), 6u + 1 + 2);  // the pyramid, its ground, two of the three balls

  Echo echo("--topics bodies --timeout 4");
  const std::vector<Json> lines = echo.finish();
  std::set<std::uint64_t> described;
  for (const Json& line : lines)
    if (!line.contains("removed")) {
      described.insert(line["id"].get<std::uint64_t>());
      if (line["id"] == spawned.ids(0)) {
        EXPECT_EQ(line["shape"], "sphere");
        EXPECT_EQ(line["radius"], 0.3);
      }
    }
  EXPECT_EQ(described, live);
  EXPECT_FALSE(described.contains(spawned.ids(1)));
}

// A compound's parts reach the bodies topic as the gRPC stream describes them: each part's shape,
// sizes, a hull's vertices and its pose in the body's frame (whose origin is the centre of mass,
// so not the poses spawned), bit for bit.
TEST_F(DdsTest, ACompoundsPartsReachTheBodiesTopicAsTheStreamDescribesThem) {
  Server server;
  server.start({"--paused", "--dds", "--dds-domain", own_domain(), "--standard", "pyramid:2"});
  auto stub = connect(server);
  v1::SpawnBodiesRequest spawn;
  v1::BodySpec* body = spawn.add_bodies();
  body->mutable_position()->set_z(3);
  v1::Compound* compound = body->mutable_shape()->mutable_compound();
  const auto part_at = [&](double x, double y, double z) {
    v1::CompoundPart* part = compound->add_parts();
    part->mutable_position()->set_x(x);
    part->mutable_position()->set_y(y);
    part->mutable_position()->set_z(z);
    return part;
  };
  v1::CompoundPart* slab = part_at(0, 0, 0.4);
  slab->mutable_shape()->mutable_box()->mutable_size()->set_x(1.2);
  slab->mutable_shape()->mutable_box()->mutable_size()->set_y(0.8);
  slab->mutable_shape()->mutable_box()->mutable_size()->set_z(0.1);
  slab->mutable_orientation()->set_w(std::sqrt(0.5));
  slab->mutable_orientation()->set_z(std::sqrt(0.5));
  part_at(0.5, 0, 0)->mutable_shape()->mutable_sphere()->set_radius(0.2);
  v1::Capsule* leg = part_at(-0.3, 0.1, 0)->mutable_shape()->mutable_capsule();
  leg->set_radius(0.05);
  leg->set_half_height(0.3);
  v1::Hull* wedge = part_at(0, -0.4, -0.2)->mutable_shape()->mutable_hull();
  for (double coordinate : {0., 0., 0., 0.3, 0., 0., 0., 0.3, 0., 0., 0., 0.3, 0.2, 0.2, 0.2})
    wedge->add_points(coordinate);

  grpc::ClientContext stream_context;
  auto reader = stub->StreamFrames(&stream_context, {});
  std::mutex mutex;
  std::map<std::uint64_t, v1::BodyDescription> described;
  std::thread streaming([&] {
    v1::Frame frame;
    while (reader->Read(&frame)) {
      std::lock_guard lock(mutex);
      for (const v1::BodyDescription& added : frame.added())
        described[added.id()] = added;
    }
  });
  v1::SpawnBodiesResponse spawned;
  {
    grpc::ClientContext context;
    ASSERT_TRUE(stub->SpawnBodies(&context, spawn, &spawned).ok());
  }
  step_one_at_a_time(*stub, 2);
  Echo echo("--topics bodies --timeout 3");
  const std::vector<Json> lines = echo.finish();
  stream_context.TryCancel();
  streaming.join();

  const std::uint64_t id = spawned.ids(0);
  ASSERT_TRUE(described.contains(id));
  const v1::Compound& parts = described.at(id).shape().compound();
  ASSERT_EQ(parts.parts_size(), 4);
  int seen = 0;
  for (const Json& line : lines) {
    if (line.contains("removed") || line["id"] != id) continue;
    ++seen;
    ASSERT_EQ(line["shape"], "compound");
    ASSERT_EQ(line["parts"].size(), 4u);
    const char* kinds[] = {"box", "sphere", "capsule", "hull"};
    for (int i = 0; i < 4; ++i) {
      const Json& part = line["parts"][i];
      const v1::CompoundPart& expected = parts.parts(i);
      EXPECT_EQ(part["shape"], kinds[i]);
      EXPECT_EQ(part["p"],
                Json({expected.position().x(), expected.position().y(), expected.position().z()}));
      EXPECT_EQ(part["q"], Json({expected.orientation().w(), expected.orientation().x(),
                                 expected.orientation().y(), expected.orientation().z()}));
    }
    const v1::Vec3& size = parts.parts(0).shape().box().size();
    EXPECT_EQ(line["parts"][0]["half_extents"],
              Json({0.5 * size.x(), 0.5 * size.y(), 0.5 * size.z()}));
    EXPECT_EQ(line["parts"][1]["radius"], parts.parts(1).shape().sphere().radius());
    EXPECT_EQ(line["parts"][2]["radius"], parts.parts(2).shape().capsule().radius());
    EXPECT_EQ(line["parts"][2]["half_height"], parts.parts(2).shape().capsule().half_height());
    const auto& points = parts.parts(3).shape().hull().points();
    Json vertices = Json::array();
    for (int k = 0; k + 2 < points.size(); k += 3)
      vertices.push_back({points[k], points[k + 1], points[k + 2]});
    EXPECT_EQ(line["parts"][3]["hull_vertices"], vertices);
    EXPECT_EQ(vertices.size(), 5u);
  }
  EXPECT_EQ(seen, 1);
  // The parts are where the body's frame puts them: the centre of mass moved off the spawn's
  // origin, so the sphere's part is not at the 0.5, 0, 0 it was given.
  EXPECT_NE(parts.parts(1).position().z(), 0.0);
}

// A world with joints publishes sensor_msgs/JointState on /joint_states (as robot_state_publisher
// and RViz read it): each joint named "joint_<id>", its position, velocity and effort equal to the
// gRPC frame's joint states of the same step (frames with joints asked for).
TEST_F(DdsTest, JointStatesReachADdsReaderAsTheFramesCarryThem) {
  Server server;
  server.start(
      {"--paused", "--dds", "--dds-domain", own_domain(), "--standard", "double-pendulum"});
  auto stub = connect(server);
  std::mutex mutex;
  std::map<long long, v1::Frame> frames;  // by simulated time, in microseconds
  grpc::ClientContext stream_context;
  v1::StreamFramesRequest request;
  request.set_joints(true);
  auto reader = stub->StreamFrames(&stream_context, request);
  std::thread streaming([&] {
    v1::Frame frame;
    while (reader->Read(&frame)) {
      std::lock_guard lock(mutex);
      frames[std::llround(frame.time() * 1e6)] = frame;
    }
  });
  Echo echo("--topics joint_states --timeout 4");
  std::this_thread::sleep_for(1500ms);  // discovery
  step_one_at_a_time(*stub, 15);
  const std::vector<Json> lines = echo.finish();
  stream_context.TryCancel();
  streaming.join();
  int equal = 0;
  for (const Json& line : lines) {
    ASSERT_EQ(line["topic"], "joint_states");
    const auto found = frames.find(std::llround(line["time"].get<double>() * 1e6));
    if (found == frames.end() || found->second.step() == 0) continue;
    const v1::JointStates& joints = found->second.joints();
    ASSERT_EQ(joints.ids_size(), 2);  // the double pendulum's two hinges
    ASSERT_EQ(line["name"].size(), 2u);
    for (int i = 0; i < joints.ids_size(); ++i) {
      EXPECT_NE(joints.ids(i), 0u);  // the scene's joints have ids from the start
      EXPECT_EQ(line["name"][i], "joint_" + std::to_string(joints.ids(i)));
      EXPECT_EQ(line["position"][i].get<double>(), joints.positions(i));
      EXPECT_EQ(line["velocity"][i].get<double>(), joints.speeds(i));
      EXPECT_EQ(line["effort"][i].get<double>(), joints.efforts(i));
    }
    ++equal;
  }
  EXPECT_GE(equal, 10);  // ROS 2's default QoS is reliable: nearly all 15 steps
}

// Issue 31 (5): keyed by body id (never used again), Cyclone DDS 0.10 kept about 300 bytes for
// every body ever published, disposed or not: 133 -> 654 MB over 2 million bodies. Keyed by
// instances used again, the keys are at most the most bodies alive at once, and the server's
// memory stays where it was while bodies come and go.
TEST_F(DdsTest, BodiesComingAndGoingLeaveNoMemoryBehind) {
  Server server;
  server.start({"--dds", "--dds-domain", own_domain(), "--standard", "pyramid:3"});
  auto stub = connect(server);
  auto churn = [&](int rounds) {
    v1::SpawnBodiesRequest spawn;
    for (int i = 0; i < 100; ++i) {
      v1::BodySpec* ball = spawn.add_bodies();
      ball->mutable_shape()->mutable_sphere()->set_radius(0.1);
      ball->mutable_position()->set_x(0.3 * i);
      ball->mutable_position()->set_z(50);
    }
    for (int round = 0; round < rounds; ++round) {
      v1::SpawnBodiesResponse spawned;
      grpc::ClientContext spawn_context;
      ASSERT_TRUE(stub->SpawnBodies(&spawn_context, spawn, &spawned).ok());
      std::this_thread::sleep_for(2ms);  // a frame or two, so the catalogue publishes them
      v1::RemoveBodiesRequest remove;
      *remove.mutable_ids() = spawned.ids();
      grpc::ClientContext remove_context;
      v1::RemoveBodiesResponse removed;
      ASSERT_TRUE(stub->RemoveBodies(&remove_context, remove, &removed).ok());
    }
  };
  auto resident = [&] {
    std::ifstream status("/proc/" + std::to_string(server.pid) + "/status");
    std::string key;
    std::size_t kib = 0;
    while (status >> key)
      if (key == "VmRSS:" && status >> kib) break;
    return kib * 1024;
  };
  ASSERT_NO_FATAL_FAILURE(churn(100));  // warm: the allocator's pools, the first instances
  const std::size_t before = resident();
  ASSERT_NO_FATAL_FAILURE(churn(500));  // 50,000 more bodies made and removed
  const std::size_t after = resident();
#ifndef TUMBLE_SANITIZED  // a sanitizer's quarantine keeps freed memory
  EXPECT_LT(after, before + 6 * (1 << 20)) << before / 1024 << " -> " << after / 1024 << " KiB";
#endif

  // A body spawned now takes an instance used before: no more instances than bodies ever alive
  // together (the pyramid's 7 and 100 at a time).
  {
    v1::SpawnBodiesRequest spawn;
    spawn.add_bodies()->mutable_shape()->mutable_sphere()->set_radius(0.2);
    grpc::ClientContext context;
    v1::SpawnBodiesResponse spawned;
    ASSERT_TRUE(stub->SpawnBodies(&context, spawn, &spawned).ok());
  }
  std::this_thread::sleep_for(200ms);
  Echo echo("--topics bodies --timeout 4");
  const std::vector<Json> lines = echo.finish();
  int described = 0;
  for (const Json& line : lines)
    if (!line.contains("removed")) {
      ++described;
      EXPECT_LT(line["instance"].get<std::uint32_t>(), 110u) << line.dump();
    }
  EXPECT_EQ(described, 6 + 1 + 1);  // the pyramid, its ground and the ball
}

}  // namespace
}  // namespace tumble::testing
