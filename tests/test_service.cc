// The gRPC service through an in-process channel: spawning, removing, reading, control and the
// frame stream; bad input is refused with the right code and a message naming the field, and
// leaves the world as it was.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>
#include <array>
#include <map>

#include <cstring>

#include <set>
#include <thread>
#include <tuple>

#include "scene_runner.h"
#include "service.h"
#include "tumble/v1/snapshot.pb.h"

namespace tumble::server {
namespace {

using namespace std::chrono_literals;

class ServiceTest : public ::testing::Test {
 protected:
  ServiceTest()
      : host_(make_world(pile_scene(8)).value(), 1.0 / 60, 0),
        service_(host_, {.max_bodies = 100, .token = "", .world = {}}, pile_scene(8)) {
    grpc::ServerBuilder builder;
    service_.register_on(builder);
    server_ = builder.BuildAndStart();
    stub_ = v1::World::NewStub(server_->InProcessChannel(grpc::ChannelArguments()));
  }
  ~ServiceTest() override {
    service_.shut_down();
    server_->Shutdown();
  }

  std::uint32_t body_count() {
    grpc::ClientContext context;
    v1::GetInfoResponse info;
    EXPECT_TRUE(stub_->GetInfo(&context, {}, &info).ok());
    return info.body_count();
  }

  // Every body's id, in the order GetBodies lists them (the world's slots).
  std::vector<std::uint64_t> ids() {
    grpc::ClientContext context;
    v1::GetBodiesResponse bodies;
    EXPECT_TRUE(stub_->GetBodies(&context, {}, &bodies).ok());
    std::vector<std::uint64_t> out;
    for (const v1::BodyState& state : bodies.states())
      out.push_back(state.id());
    return out;
  }

  static v1::BodySpec ball(double z) {
    v1::BodySpec spec;
    spec.mutable_shape()->mutable_sphere()->set_radius(0.25);
    spec.mutable_position()->set_z(z);
    return spec;
  }

  WorldHost host_;
  WorldService service_;
  std::unique_ptr<grpc::Server> server_;
  std::unique_ptr<v1::World::Stub> stub_;
};

TEST_F(ServiceTest, SpawnReadAndRemove) {
  v1::SpawnBodiesRequest request;
  for (int i = 0; i < 3; ++i)
    *request.add_bodies() = ball(10 + i);
  v1::SpawnBodiesResponse spawned;
  grpc::ClientContext spawn_context;
  ASSERT_TRUE(stub_->SpawnBodies(&spawn_context, request, &spawned).ok());
  ASSERT_EQ(spawned.ids_size(), 3);
  EXPECT_EQ(body_count(), 12u);

  v1::GetBodiesRequest get;
  get.add_ids(spawned.ids(1));
  v1::GetBodiesResponse bodies;
  grpc::ClientContext get_context;
  ASSERT_TRUE(stub_->GetBodies(&get_context, get, &bodies).ok());
  ASSERT_EQ(bodies.states_size(), 1);
  EXPECT_EQ(bodies.states(0).position().z(), 11);
  EXPECT_EQ(bodies.descriptions(0).shape().sphere().radius(), 0.25);

  v1::RemoveBodiesRequest remove;
  remove.add_ids(spawned.ids(0));
  remove.add_ids(spawned.ids(2));
  grpc::ClientContext remove_context;
  v1::RemoveBodiesResponse removed;
  ASSERT_TRUE(stub_->RemoveBodies(&remove_context, remove, &removed).ok());
  EXPECT_EQ(body_count(), 10u);
}

TEST_F(ServiceTest, BadInputIsRefusedByFieldAndChangesNothing) {
  const std::uint32_t before = body_count();
  {  // one bad body refuses the batch
    v1::SpawnBodiesRequest request;
    *request.add_bodies() = ball(3);
    *request.add_bodies() = ball(4);
    request.mutable_bodies(1)->mutable_orientation()->set_w(0);  // the zero quaternion
    request.mutable_bodies(1)->mutable_orientation()->set_x(0);
    grpc::ClientContext context;
    v1::SpawnBodiesResponse response;
    const grpc::Status status = stub_->SpawnBodies(&context, request, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_EQ(status.error_message().rfind("bodies[1].orientation:", 0), 0u)
        << status.error_message();
  }
  // Refused by the engine, which names the fields as its own types have them (shape.radius,
  // shape.points, shape.parts[1].shape.points): answered in the message's terms.
  const auto flat_hull = [](v1::Shape* shape) {
    for (double coordinate : {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0})
      shape->mutable_hull()->add_points(coordinate);
  };
  const std::pair<std::function<void(v1::BodySpec*)>, const char*> engine_refusals[] = {
      {[](v1::BodySpec* spec) {  // past the world's limits
         spec->mutable_shape()->mutable_sphere()->set_radius(1e-7);
         spec->set_mass(1);
       },
       "bodies[1].shape.sphere.radius: "},
      {[&](v1::BodySpec* spec) { flat_hull(spec->mutable_shape()); },
       "bodies[1].shape.hull.points: coplanar"},
      {[&](v1::BodySpec* spec) {
         v1::Compound* compound = spec->mutable_shape()->mutable_compound();
         compound->add_parts()->mutable_shape()->mutable_sphere()->set_radius(0.5);
         flat_hull(compound->add_parts()->mutable_shape());
       },
       "bodies[1].shape.compound.parts[1].shape.hull.points: coplanar"},
  };
  for (const auto& [spoil, field] : engine_refusals) {
    v1::SpawnBodiesRequest request;
    *request.add_bodies() = ball(3);
    *request.add_bodies() = ball(4);
    spoil(request.mutable_bodies(1));
    grpc::ClientContext context;
    v1::SpawnBodiesResponse response;
    const grpc::Status status = stub_->SpawnBodies(&context, request, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << field;
    EXPECT_EQ(status.error_message().rfind(field, 0), 0u) << status.error_message();
  }
  {  // over the body limit
    v1::SpawnBodiesRequest request;
    for (int i = 0; i < 100; ++i)
      *request.add_bodies() = ball(3 + i);
    grpc::ClientContext context;
    v1::SpawnBodiesResponse response;
    EXPECT_EQ(stub_->SpawnBodies(&context, request, &response).error_code(),
              grpc::StatusCode::RESOURCE_EXHAUSTED);
  }
  {  // one unknown id refuses the whole removal
    v1::RemoveBodiesRequest request;
    request.add_ids(ids()[1]);
    request.add_ids(999999);
    grpc::ClientContext context;
    v1::RemoveBodiesResponse response;
    const grpc::Status status = stub_->RemoveBodies(&context, request, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);
    EXPECT_EQ(status.error_message().rfind("ids[1]:", 0), 0u) << status.error_message();
  }
  {  // control settings are checked before anything changes
    v1::ControlRequest request;
    request.mutable_settings()->set_dt(-1);
    request.set_step(5);
    grpc::ClientContext context;
    v1::ControlResponse response;
    EXPECT_EQ(stub_->Control(&context, request, &response).error_code(),
              grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_EQ(host_.status().step, 0u);
  }
  EXPECT_EQ(body_count(), before);
}

TEST_F(ServiceTest, SetStateAndImpulsesApplyWholeBatchesOnly) {
  auto state_of = [&](std::uint64_t id) {
    v1::GetBodiesRequest get;
    get.add_ids(id);
    v1::GetBodiesResponse bodies;
    grpc::ClientContext context;
    EXPECT_TRUE(stub_->GetBodies(&context, get, &bodies).ok());
    return bodies.states(0);
  };
  const std::uint64_t a = ids()[1], b = ids()[2];
  {
    v1::SetBodyStateRequest request;
    auto* first = request.add_updates();
    first->set_id(a);
    first->mutable_position()->set_z(42);
    auto* second = request.add_updates();
    second->set_id(b);
    second->mutable_orientation()->set_w(3);  // not a unit quaternion: the batch is refused
    grpc::ClientContext context;
    v1::SetBodyStateResponse response;
    const grpc::Status status = stub_->SetBodyState(&context, request, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_EQ(status.error_message().rfind("updates[1].orientation:", 0), 0u)
        << status.error_message();
    EXPECT_NE(state_of(a).position().z(), 42);  // the first update was not applied either
    second->mutable_orientation()->set_w(1);
    grpc::ClientContext again;
    ASSERT_TRUE(stub_->SetBodyState(&again, request, &response).ok());
    EXPECT_EQ(state_of(a).position().z(), 42);
  }
  {
    v1::ApplyImpulseRequest request;
    auto* push = request.add_impulses();
    push->set_id(b);
    push->mutable_impulse()->set_x(3);  // 3 N s on a 1 kg box
    grpc::ClientContext context;
    v1::ApplyImpulseResponse response;
    ASSERT_TRUE(stub_->ApplyImpulse(&context, request, &response).ok());
    EXPECT_EQ(state_of(b).linear_velocity().x(), 3);
    push->set_id(ids()[0]);  // the ground
    grpc::ClientContext ground;
    EXPECT_EQ(stub_->ApplyImpulse(&ground, request, &response).error_code(),
              grpc::StatusCode::INVALID_ARGUMENT);
    push->set_id(77777);
    grpc::ClientContext unknown;
    EXPECT_EQ(stub_->ApplyImpulse(&unknown, request, &response).error_code(),
              grpc::StatusCode::NOT_FOUND);
  }
}

TEST_F(ServiceTest, ControlChangesSettingsAllOrNothingAndResets) {
  {
    v1::ControlRequest request;
    request.mutable_settings()->set_solver(v1::SOLVER_KIND_SOFT);
    request.mutable_settings()->mutable_gravity()->set_z(-1);
    request.mutable_settings()->set_substeps(0);  // refused: nothing changes
    grpc::ClientContext context;
    v1::ControlResponse response;
    const grpc::Status status = stub_->Control(&context, request, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_NE(status.error_message().find("substeps"), std::string::npos) << status.error_message();
    request.mutable_settings()->set_substeps(8);
    grpc::ClientContext again;
    ASSERT_TRUE(stub_->Control(&again, request, &response).ok());
    EXPECT_EQ(response.settings().solver(), v1::SOLVER_KIND_SOFT);
    EXPECT_EQ(response.settings().gravity().z(), -1);
    EXPECT_EQ(response.settings().substeps(), 8);
  }
  {  // run, spawn, then reset: the scene as loaded, at step 0
    v1::ControlRequest step;
    step.set_step(5);
    grpc::ClientContext step_context;
    v1::ControlResponse response;
    ASSERT_TRUE(stub_->Control(&step_context, step, &response).ok());
    ASSERT_TRUE(host_.wait_idle(std::chrono::seconds(30)));
    v1::SpawnBodiesRequest spawn;
    *spawn.add_bodies() = ball(9);
    grpc::ClientContext spawn_context;
    v1::SpawnBodiesResponse spawned;
    ASSERT_TRUE(stub_->SpawnBodies(&spawn_context, spawn, &spawned).ok());
    EXPECT_EQ(body_count(), 10u);
    v1::ControlRequest reset;
    reset.set_reset(true);
    grpc::ClientContext reset_context;
    ASSERT_TRUE(stub_->Control(&reset_context, reset, &response).ok());
    EXPECT_EQ(body_count(), 9u);
    EXPECT_EQ(response.step(), 0u);
  }
}

// The pgs sweeps and the joints' position passes, the solver's cost against its accuracy, change
// while the world runs; a value out of range is refused by name and changes nothing.
TEST_F(ServiceTest, ControlChangesTheSweepsAndJointPassesWhileRunning) {
  const auto control = [&](int iterations, int passes, v1::ControlResponse* response) {
    v1::ControlRequest request;
    request.mutable_settings()->set_iterations(iterations);
    request.mutable_settings()->set_joint_position_passes(passes);
    request.mutable_settings()->set_solver(v1::SOLVER_KIND_PGS);
    request.set_step(2);
    grpc::ClientContext context;
    return stub_->Control(&context, request, response);
  };
  const auto settings_now = [&] {
    v1::GetInfoRequest request;
    grpc::ClientContext context;
    v1::GetInfoResponse response;
    EXPECT_TRUE(stub_->GetInfo(&context, request, &response).ok());
    return response.settings();
  };
  const v1::RunSettings before = settings_now();
  EXPECT_EQ(before.iterations(), SolverSettings{}.iterations);
  EXPECT_EQ(before.joint_position_passes(), SolverSettings{}.joint_position_passes);
  for (const auto& [iterations, passes, field] :
       {std::tuple{0, 2, "iterations"}, std::tuple{1001, 2, "iterations"},
        std::tuple{20, -1, "joint_position_passes"}, std::tuple{20, 1001, "joint_position_passes"}}) {
    v1::ControlResponse response;
    const grpc::Status status = control(iterations, passes, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << field;
    // Named as the request names it: RunSettings carries them at its top level.
    EXPECT_EQ(status.error_message().rfind("settings." + std::string(field) + ": must be in", 0), 0u)
        << status.error_message();
    const v1::RunSettings now = settings_now();
    EXPECT_EQ(now.iterations(), before.iterations());
    EXPECT_EQ(now.joint_position_passes(), before.joint_position_passes());
    EXPECT_EQ(now.solver(), before.solver());
  }
  v1::ControlResponse response;
  ASSERT_TRUE(control(20, 0, &response).ok());
  EXPECT_EQ(response.settings().iterations(), 20);
  EXPECT_EQ(response.settings().joint_position_passes(), 0);
  ASSERT_TRUE(host_.wait_idle(std::chrono::seconds(30)));
  const v1::RunSettings now = settings_now();
  EXPECT_EQ(now.iterations(), 20);
  EXPECT_EQ(now.joint_position_passes(), 0);
  EXPECT_EQ(now.solver(), v1::SOLVER_KIND_PGS);
}

TEST_F(ServiceTest, LoadSceneReplacesTheWorldOrNothing) {
  {
    v1::LoadSceneRequest request;
    request.set_scene_json(R"({"name": "bad", "bodies": [{"shape": "box", "size": [1, -1, 1]}]})");
    grpc::ClientContext context;
    v1::LoadSceneResponse response;
    const grpc::Status status = stub_->LoadScene(&context, request, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_NE(status.error_message().find("bodies[0].size[1]"), std::string::npos)
        << status.error_message();
    EXPECT_EQ(body_count(), 9u);
  }
  {
    v1::LoadSceneRequest request;
    request.set_builtin("pyramid:5");
    grpc::ClientContext context;
    v1::LoadSceneResponse response;
    ASSERT_TRUE(stub_->LoadScene(&context, request, &response).ok());
    EXPECT_EQ(response.name(), "pyramid-5");
    EXPECT_EQ(response.ids_size(), 16);  // ground and 15 boxes
    EXPECT_EQ(body_count(), 16u);
  }
}

// A client cannot widen the server's limits with the limits of a scene it loads.
TEST_F(ServiceTest, TheServersLimitsHoldForEveryLoadedScene) {
  const std::vector<std::uint64_t> before = ids();
  v1::LoadSceneRequest request;
  request.set_scene_json(R"({"limits": {"max_size": 1e9},
                             "bodies": [{"shape": "sphere", "radius": 1e6, "mass": 1}]})");
  grpc::ClientContext context;
  v1::LoadSceneResponse response;
  const grpc::Status status = stub_->LoadScene(&context, request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(status.error_message().find("bodies[0].shape.radius"), std::string::npos)
      << status.error_message();
  EXPECT_NE(status.error_message().find("max_size"), std::string::npos);
  EXPECT_EQ(ids(), before);

  v1::ControlRequest slow;
  slow.mutable_settings()->set_dt(5);
  grpc::ClientContext control_context;
  v1::ControlResponse control_response;
  const grpc::Status refused = stub_->Control(&control_context, slow, &control_response);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(refused.error_message().find("max_time_step"), std::string::npos);
}

TEST_F(ServiceTest, StreamDescribesBodiesThenSendsPoses) {
  v1::StreamFramesRequest request;
  request.set_stats(true);
  grpc::ClientContext context;
  auto reader = stub_->StreamFrames(&context, request);
  // The stream subscribes when the server runs the call: step only once it has.
  for (int i = 0; i < 500 && host_.status().subscribers == 0; ++i)
    std::this_thread::sleep_for(10ms);
  ASSERT_EQ(host_.status().subscribers, 1u);
  {
    v1::ControlRequest control;
    control.set_step(20);
    grpc::ClientContext control_context;
    v1::ControlResponse response;
    ASSERT_TRUE(stub_->Control(&control_context, control, &response).ok());
  }
  v1::Frame first;
  ASSERT_TRUE(reader->Read(&first));
  EXPECT_EQ(first.ids_size(), 9);
  EXPECT_EQ(first.added_size(), 9);  // every body described in the first frame
  EXPECT_EQ(first.positions_size(), 27);
  EXPECT_TRUE(first.has_stats());
  // Later frames carry poses only; the step count reaches 20.
  v1::Frame frame = first;
  while (frame.step() < 20 && reader->Read(&frame))
    EXPECT_EQ(frame.added_size(), 0);
  EXPECT_EQ(frame.step(), 20u);
  context.TryCancel();
  reader->Finish();
}

// Changes only: after the first frame, a frame lists the bodies changed since the previous one
// sent, so a settled pile costs nothing and one falling ball one body a frame; merged in order,
// the frames give every body exactly where the world has it, frames dropped on the way or not.
TEST_F(ServiceTest, ChangesOnlyFramesCarryWhatChangedAndAddUpToTheWorld) {
  v1::StreamFramesRequest request;
  request.set_changes_only(true);
  request.set_stats(true);
  grpc::ClientContext context;
  auto reader = stub_->StreamFrames(&context, request);
  for (int i = 0; i < 500 && host_.status().subscribers == 0; ++i)
    std::this_thread::sleep_for(10ms);
  ASSERT_EQ(host_.status().subscribers, 1u);
  auto step = [&](std::uint64_t n) {
    v1::ControlRequest control;
    control.set_step(n);
    grpc::ClientContext control_context;
    v1::ControlResponse response;
    ASSERT_TRUE(stub_->Control(&control_context, control, &response).ok());
    ASSERT_TRUE(host_.wait_idle(std::chrono::seconds(60)));
  };
  std::map<std::uint64_t, std::array<double, 3>> merged;
  v1::Frame frame;
  bool first = true;
  // Frames up to step `last`, merged; whatever the stream coalesced on the way.
  auto read_until = [&](std::uint64_t last) {
    while (reader->Read(&frame)) {
      EXPECT_EQ(frame.changes_only(), !first) << "step " << frame.step();
      if (first) EXPECT_EQ(frame.ids_size(), 9);
      first = false;
      for (int i = 0; i < frame.ids_size(); ++i)
        merged[frame.ids(i)] = {frame.positions(3 * i), frame.positions(3 * i + 1),
                                frame.positions(3 * i + 2)};
      if (frame.step() >= last) return;
    }
    ADD_FAILURE() << "the stream ended";
  };
  step(900);  // 15 s: the pile settles and sleeps
  read_until(900);
  ASSERT_EQ(frame.stats().sleeping_bodies(), 8u);  // the pile sleeps (the ground is static)
  v1::SpawnBodiesRequest spawn;
  *spawn.add_bodies() = ball(30);
  spawn.mutable_bodies(0)->mutable_position()->set_x(40);  // far from the pile
  grpc::ClientContext spawn_context;
  v1::SpawnBodiesResponse spawned;
  ASSERT_TRUE(stub_->SpawnBodies(&spawn_context, spawn, &spawned).ok());
  for (std::uint64_t k = 901; k <= 930; ++k) {
    step(1);
    read_until(k);
    ASSERT_EQ(frame.ids_size(), 1) << "step " << k;  // the falling ball alone
    EXPECT_EQ(frame.ids(0), spawned.ids(0));
  }
  grpc::ClientContext get_context;
  v1::GetBodiesResponse world;
  ASSERT_TRUE(stub_->GetBodies(&get_context, {}, &world).ok());
  ASSERT_EQ(merged.size(), static_cast<std::size_t>(world.states_size()));
  for (const v1::BodyState& state : world.states()) {
    const auto& p = merged.at(state.id());
    EXPECT_EQ(p[0], state.position().x());
    EXPECT_EQ(p[1], state.position().y());
    EXPECT_EQ(p[2], state.position().z());
  }
  context.TryCancel();
  reader->Finish();
}

// Helpers for the snapshot tests: run n steps and wait; every body's state.
class SnapshotTest : public ServiceTest {
 protected:
  void run_steps(std::uint64_t n) {
    v1::ControlRequest step;
    step.set_step(n);
    grpc::ClientContext context;
    v1::ControlResponse response;
    ASSERT_TRUE(stub_->Control(&context, step, &response).ok());
    ASSERT_TRUE(host_.wait_idle(std::chrono::seconds(60)));
  }
  v1::GetBodiesResponse bodies() {
    grpc::ClientContext context;
    v1::GetBodiesResponse response;
    EXPECT_TRUE(stub_->GetBodies(&context, {}, &response).ok());
    return response;
  }
  v1::SnapshotResponse snapshot() {
    grpc::ClientContext context;
    v1::SnapshotResponse response;
    EXPECT_TRUE(stub_->Snapshot(&context, {}, &response).ok());
    return response;
  }
  grpc::Status restore(const std::string& state, v1::RestoreResponse* answer = nullptr) {
    v1::RestoreRequest request;
    request.set_state(state);
    grpc::ClientContext context;
    v1::RestoreResponse response;
    const grpc::Status status = stub_->Restore(&context, request, &response);
    if (answer != nullptr) *answer = response;
    return status;
  }
  std::vector<std::uint64_t> spawn_balls(int n) {
    v1::SpawnBodiesRequest request;
    for (int i = 0; i < n; ++i)
      *request.add_bodies() = ball(5 + i);
    grpc::ClientContext context;
    v1::SpawnBodiesResponse response;
    EXPECT_TRUE(stub_->SpawnBodies(&context, request, &response).ok());
    return {response.ids().begin(), response.ids().end()};
  }
  void control(const v1::ControlRequest& request) {
    grpc::ClientContext context;
    v1::ControlResponse response;
    ASSERT_TRUE(stub_->Control(&context, request, &response).ok());
  }
};

// Issue 17, defect 3: after a reset, a scene load or a restore, new bodies once took the ids of
// old ones, so a client's remove of "its" box deleted somebody else's sphere.
TEST_F(SnapshotTest, IdsNeverNameAnotherBodyAcrossResetLoadAndRestore) {
  std::set<std::uint64_t> seen;
  // Every id handed out must be new, except a restored body's own.
  auto all_new = [&](const std::vector<std::uint64_t>& ids) {
    for (std::uint64_t id : ids)
      EXPECT_TRUE(seen.insert(id).second) << "id " << id << " was given before";
  };
  all_new(ids());
  const std::vector<std::uint64_t> mine = spawn_balls(2);
  all_new(mine);
  v1::ControlRequest reset;
  reset.set_reset(true);
  control(reset);
  all_new(ids());
  all_new(spawn_balls(2));
  {  // the balls spawned before the reset are gone: removing one is refused, nothing removed
    const std::size_t count = body_count();
    v1::RemoveBodiesRequest request;
    request.add_ids(mine[0]);
    grpc::ClientContext context;
    v1::RemoveBodiesResponse response;
    EXPECT_EQ(stub_->RemoveBodies(&context, request, &response).error_code(),
              grpc::StatusCode::NOT_FOUND);
    EXPECT_EQ(body_count(), count);
  }
  v1::LoadSceneRequest load;
  load.set_builtin("pyramid:3");
  grpc::ClientContext load_context;
  v1::LoadSceneResponse loaded;
  ASSERT_TRUE(stub_->LoadScene(&load_context, load, &loaded).ok());
  all_new({loaded.ids().begin(), loaded.ids().end()});

  const std::vector<std::uint64_t> saved_ids = ids();
  const std::string saved = snapshot().state();
  all_new(spawn_balls(3));
  v1::RestoreResponse restored;
  ASSERT_TRUE(restore(saved, &restored).ok());
  EXPECT_EQ(ids(), saved_ids);  // a snapshot of this server: the same bodies, the same ids
  EXPECT_TRUE(restored.new_ids().empty());
  all_new(spawn_balls(2));  // not the ids of the three spawned after the snapshot

  // A snapshot from another server: its ids could be ours for other bodies, so all are new.
  v1::snapshot::WorldSnapshot foreign;
  ASSERT_TRUE(foreign.ParseFromString(saved));
  foreign.set_server_instance(foreign.server_instance() + 1);
  ASSERT_TRUE(restore(foreign.SerializeAsString(), &restored).ok());
  all_new(ids());
  ASSERT_EQ(restored.new_ids().size(), saved_ids.size());
  for (std::uint64_t old_id : saved_ids)
    EXPECT_TRUE(restored.new_ids().contains(old_id)) << old_id;
}

TEST_F(SnapshotTest, RestoreContinuesTheRunBitForBit) {
  v1::SpawnBodiesRequest spawn;
  *spawn.add_bodies() = ball(6);
  spawn.mutable_bodies(0)->set_color(0xff8000ffu);
  grpc::ClientContext spawn_context;
  v1::SpawnBodiesResponse spawned;
  ASSERT_TRUE(stub_->SpawnBodies(&spawn_context, spawn, &spawned).ok());
  run_steps(50);  // the pile is landing: contacts and warm starts in play
  const v1::SnapshotResponse saved = snapshot();
  EXPECT_EQ(saved.step(), 50u);
  v1::snapshot::WorldSnapshot parsed;
  ASSERT_TRUE(parsed.ParseFromString(saved.state()));
  ASSERT_GT(World::state_sizes(parsed.engine_state()).value().contact_pairs, 0u);
  run_steps(60);
  const v1::GetBodiesResponse straight = bodies();

  ASSERT_TRUE(restore(saved.state()).ok());
  EXPECT_EQ(bodies().step(), 50u);
  run_steps(60);
  const v1::GetBodiesResponse resumed = bodies();
  ASSERT_EQ(resumed.step(), 110u);
  ASSERT_EQ(resumed.states_size(), straight.states_size());
  for (int i = 0; i < straight.states_size(); ++i) {
    // Bit for bit: the serialized states are the same bytes.
    EXPECT_EQ(resumed.states(i).SerializeAsString(), straight.states(i).SerializeAsString())
        << "body " << i;
    EXPECT_EQ(resumed.descriptions(i).color(), straight.descriptions(i).color());
  }
  bool coloured = false;
  for (const auto& d : resumed.descriptions())
    coloured |= d.id() == spawned.ids(0) && d.color() == 0xff8000ffu;
  EXPECT_TRUE(coloured);
}

TEST_F(SnapshotTest, BadSnapshotsAreRefusedAndChangeNothing) {
  run_steps(10);
  const std::string good = snapshot().state();
  const std::string before = bodies().SerializeAsString();
  grpc::Status status = restore("not a snapshot at all");
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(status.error_message().find("state"), std::string::npos) << status.error_message();

  // A well-formed snapshot with one bad number in the engine's bytes: the field is named. Slot
  // 3's position is found by its value (three doubles, World::save_state's layout).
  v1::snapshot::WorldSnapshot bad;
  ASSERT_TRUE(bad.ParseFromString(good));
  std::string& engine = *bad.mutable_engine_state();
  const World saved = World::from_state(WorldSettings{}, engine).value();
  const Vec3 position = saved.body(saved.id_at(3)).position();
  const std::size_t at =
      engine.find(std::string(reinterpret_cast<const char*>(position.data()), 24));
  ASSERT_NE(at, std::string::npos);
  const double nan = std::nan("");
  std::memcpy(engine.data() + at + 16, &nan, 8);
  status = restore(bad.SerializeAsString());
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(status.error_message().find("state.engine_state.slots[3].position"), std::string::npos)
      << status.error_message();
  bad.ParseFromString(good);
  bad.set_version(v1::snapshot::VERSION_UNSPECIFIED);
  status = restore(bad.SerializeAsString());
  EXPECT_NE(status.error_message().find("version"), std::string::npos) << status.error_message();
  bad.ParseFromString(good);
  bad.mutable_engine_state()->resize(bad.engine_state().size() - 1);
  status = restore(bad.SerializeAsString());
  EXPECT_NE(status.error_message().find("state.engine_state.length"), std::string::npos)
      << status.error_message();
  EXPECT_EQ(bodies().SerializeAsString(), before);
}

TEST_F(SnapshotTest, AfterARestoreTheStreamDescribesEveryBodyAndRemovesOnlyThoseGone) {
  const std::string saved = snapshot().state();
  v1::SpawnBodiesRequest spawn;
  *spawn.add_bodies() = ball(6);
  grpc::ClientContext spawn_context;
  v1::SpawnBodiesResponse spawned;
  ASSERT_TRUE(stub_->SpawnBodies(&spawn_context, spawn, &spawned).ok());

  grpc::ClientContext context;
  auto reader = stub_->StreamFrames(&context, {});
  v1::Frame frame;
  ASSERT_TRUE(reader->Read(&frame));
  EXPECT_EQ(frame.added_size(), 10);
  ASSERT_TRUE(restore(saved).ok());
  ASSERT_TRUE(reader->Read(&frame));
  // A new world with the same ids: the nine it holds are described afresh, and only the ball it
  // lacks is removed. No id is both removed and added, so a client may apply the two lists in
  // either order without losing a body (it did: all ten were listed as removed too).
  ASSERT_EQ(frame.removed_size(), 1);
  EXPECT_EQ(frame.removed(0), spawned.ids(0));
  EXPECT_EQ(frame.added_size(), 9);
  EXPECT_EQ(frame.ids_size(), 9);
  std::set<std::uint64_t> added;
  for (const v1::BodyDescription& d : frame.added())
    added.insert(d.id());
  for (std::uint64_t id : frame.ids())
    EXPECT_TRUE(added.count(id)) << id;
  context.TryCancel();
  reader->Finish();
}

TEST(ServiceAuth, EveryCallNeedsTheBearerToken) {
  WorldHost host(make_world(pile_scene(8)).value(), 1.0 / 60, 0);
  WorldService service(host, {.max_bodies = 100, .token = "s3cret", .world = {}}, pile_scene(8));
  grpc::ServerBuilder builder;
  service.register_on(builder);
  std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
  auto stub = v1::World::NewStub(server->InProcessChannel(grpc::ChannelArguments()));
  for (const char* header : {"", "Bearer wrong", "Bearer s3cre", "s3cret"}) {
    grpc::ClientContext context;
    if (*header != 0) context.AddMetadata("authorization", header);
    v1::GetInfoResponse info;
    EXPECT_EQ(stub->GetInfo(&context, {}, &info).error_code(), grpc::StatusCode::UNAUTHENTICATED)
        << header;
  }
  {
    grpc::ClientContext context;
    v1::RemoveBodiesRequest remove;
    remove.add_ids(2);
    v1::RemoveBodiesResponse removed;
    EXPECT_EQ(stub->RemoveBodies(&context, remove, &removed).error_code(),
              grpc::StatusCode::UNAUTHENTICATED);
    EXPECT_EQ(host.status().bodies, 9u);  // refused before anything changed
  }
  grpc::ClientContext context;
  context.AddMetadata("authorization", "Bearer s3cret");
  v1::GetInfoResponse info;
  EXPECT_TRUE(stub->GetInfo(&context, {}, &info).ok());
  EXPECT_EQ(info.body_count(), 9u);
  service.shut_down();
  server->Shutdown();
}

}  // namespace
}  // namespace tumble::server
