// Issue 31, hostile requests round two, through an in-process channel: each request below was
// accepted, or cost far more than its size, before the gate (server/call_gate.h) and the checks
// behind it. Every refusal names what is wrong and leaves the world as it was (its snapshot
// before and after is the same, byte for byte).
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <functional>
#include <set>
#include <string>

#include "generic_call.h"
#include "request_bounds.h"
#include "scene_runner.h"
#include "service.h"
#include "tumble/v1/snapshot.pb.h"

namespace tumble::server {
namespace {

namespace pb = v1::snapshot;

constexpr std::size_t kMaxBodies = 100;

class HostileTest : public ::testing::Test {
 protected:
  HostileTest()
      : host_(make_world(pile_scene(8)).value(), 1.0 / 60, 0),
        service_(host_, {.max_bodies = kMaxBodies, .token = "", .world = {}}, pile_scene(8)) {
    grpc::ServerBuilder builder;
    service_.register_on(builder);
    server_ = builder.BuildAndStart();
    channel_ = server_->InProcessChannel(grpc::ChannelArguments());
    stub_ = v1::World::NewStub(channel_);
  }
  ~HostileTest() override {
    service_.shut_down();
    server_->Shutdown();
  }

  std::string snapshot() {
    grpc::ClientContext context;
    v1::SnapshotResponse response;
    EXPECT_TRUE(stub_->Snapshot(&context, {}, &response).ok());
    return response.state();
  }
  grpc::Status restore(const std::string& state) {
    v1::RestoreRequest request;
    request.set_state(state);
    grpc::ClientContext context;
    v1::RestoreResponse response;
    return stub_->Restore(&context, request, &response);
  }
  // `bytes` as the request of `method`, whatever they hold.
  grpc::Status raw_call(const std::string& method, const std::string& bytes) {
    grpc::ClientContext context;
    return testing::generic_unary_call(channel_, &context, "/tumble.v1.World/" + method, bytes);
  }
  std::vector<std::uint64_t> ids() {
    grpc::ClientContext context;
    v1::GetBodiesResponse bodies;
    EXPECT_TRUE(stub_->GetBodies(&context, {}, &bodies).ok());
    std::vector<std::uint64_t> out;
    for (const v1::BodyState& state : bodies.states())
      out.push_back(state.id());
    return out;
  }

  WorldHost host_;
  WorldService service_;
  std::unique_ptr<grpc::Server> server_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::World::Stub> stub_;
};

// Issue 31 (1): a million empty body specs are 2 MB on the wire and were gigabytes parsed.
TEST_F(HostileTest, ABatchOfMoreEntriesThanBodiesAllowedIsRefusedBeforeItIsParsed) {
  const std::string before = snapshot();
  std::string empties;
  for (std::size_t i = 0; i <= kMaxBodies; ++i)
    empties += std::string("\x0a\x00", 2);  // field 1, an empty BodySpec
  const grpc::Status status = raw_call("SpawnBodies", empties);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_NE(status.error_message().find("bodies: more than 100 entries"), std::string::npos)
      << status.error_message();
  EXPECT_EQ(snapshot(), before);
}

TEST_F(HostileTest, ARequestPastItsMethodsBoundIsRefusedNamingTheBound) {
  const RequestBounds bounds{.max_bodies = kMaxBodies, .max_message_bytes = 64u << 20};
  const std::size_t limit = bounds.of("GetBodies").bytes;
  EXPECT_LT(limit, 4096u);  // 100 ids, not the 64 MB of a whole world
  const grpc::Status status = raw_call("GetBodies", std::string(limit + 1, '\0'));
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_NE(status.error_message().find(std::to_string(limit)), std::string::npos)
      << status.error_message();
  // GetInfo takes an empty request: a kilobyte is the most it reads.
  EXPECT_EQ(raw_call("GetInfo", std::string(2048, '\0')).error_code(),
            grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_EQ(raw_call("NoSuchMethod", "").error_code(), grpc::StatusCode::UNIMPLEMENTED);
  EXPECT_EQ(raw_call("GetInfo", "\xff\xff").error_code(), grpc::StatusCode::INVALID_ARGUMENT);
}

// Issue 31 (2): one id repeated made a reply of millions of bodies.
TEST_F(HostileTest, GetBodiesRefusesAnIdListedTwice) {
  const std::uint64_t id = ids().at(3);
  v1::GetBodiesRequest request;
  for (int i = 0; i < 3; ++i)
    request.add_ids(id);
  grpc::ClientContext context;
  v1::GetBodiesResponse response;
  const grpc::Status status = stub_->GetBodies(&context, request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(status.error_message(), "ids[1]: listed twice");
  EXPECT_EQ(response.states_size(), 0);
}

// Issue 31 (7): each impulse was checked alone and those past the limit dropped in silence.
TEST_F(HostileTest, ImpulsesOnOneBodyAddUpAndAreCheckedAsTheirSum) {
  v1::SpawnBodiesRequest spawn;
  v1::BodySpec* ball = spawn.add_bodies();
  ball->mutable_shape()->mutable_sphere()->set_radius(0.5);
  ball->set_mass(1);
  ball->mutable_position()->set_z(50);
  grpc::ClientContext spawn_context;
  v1::SpawnBodiesResponse spawned;
  ASSERT_TRUE(stub_->SpawnBodies(&spawn_context, spawn, &spawned).ok());
  const std::uint64_t id = spawned.ids(0);
  auto push = [&](int count, double each) {
    v1::ApplyImpulseRequest request;
    for (int i = 0; i < count; ++i) {
      v1::Impulse* impulse = request.add_impulses();
      impulse->set_id(id);
      impulse->mutable_impulse()->set_x(each);
    }
    grpc::ClientContext context;
    v1::ApplyImpulseResponse response;
    return stub_->ApplyImpulse(&context, request, &response);
  };
  auto speed = [&] {
    v1::GetBodiesRequest request;
    request.add_ids(id);
    grpc::ClientContext context;
    v1::GetBodiesResponse response;
    EXPECT_TRUE(stub_->GetBodies(&context, request, &response).ok());
    return response.states(0).linear_velocity().x();
  };
  const std::string before = snapshot();
  // 3 x 40,000 N s on 1 kg is 120,000 m/s, past the 1e5 m/s limit: refused whole, naming the
  // third, and the body keeps its speed (it took 80,000 m/s and returned OK).
  const grpc::Status three = push(3, 40000);
  EXPECT_EQ(three.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(three.error_message().find("impulses[2].impulse: with the impulses before it"),
            std::string::npos)
      << three.error_message();
  EXPECT_EQ(snapshot(), before);
  EXPECT_EQ(push(10, 99999).error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(snapshot(), before);
  // Within the limit, all of them count.
  ASSERT_TRUE(push(2, 40000).ok());
  EXPECT_DOUBLE_EQ(speed(), 80000);
}

pb::WorldSnapshot decoded(const std::string& bytes) {
  pb::WorldSnapshot snapshot;
  EXPECT_TRUE(snapshot.ParseFromString(bytes));
  return snapshot;
}

// Issue 31 (3): free slots were not counted, and every one of them cost memory and step time.
// A world of the allowed bodies, all removed, leaves that many free slots, and one more body
// makes a slot too many: its snapshot lists more slots than the server allows.
TEST_F(HostileTest, ARestoredSnapshotsFreeSlotsCountAgainstTheBodiesAllowed) {
  const std::string before = snapshot();
  World emptied;
  BodyDef ball;
  ball.shape = SphereDef{0.5};
  std::vector<BodyId> made;
  for (std::size_t i = 0; i <= kMaxBodies; ++i) {
    ball.position = Vec3(2.0 * i, 0, 1);
    made.push_back(emptied.create_body(ball).value());
  }
  for (std::size_t i = 1; i < made.size(); ++i)
    ASSERT_TRUE(emptied.remove_body(made[i]));
  pb::WorldSnapshot crafted = decoded(before);
  crafted.set_engine_state(emptied.save_state());
  crafted.clear_ids();
  crafted.clear_colors();
  for (std::uint32_t slot = 0; slot < emptied.slot_count(); ++slot) {
    crafted.add_ids(slot == 0 ? 7 : 0);
    crafted.add_colors(0);
  }
  const grpc::Status status = restore(crafted.SerializeAsString());
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_NE(status.error_message().find("more than 100 entries"), std::string::npos)
      << status.error_message();
  EXPECT_EQ(snapshot(), before);
  EXPECT_TRUE(restore(before).ok());  // the world's own snapshot still restores
}

// Issue 31 (8): a restored hull was taken as stored; a spawned one is built from its points. The
// engine checks each damage (StateFormat.ARestoredHullMustBeTheHullItsVerticesMake); here, that
// the server passes its refusal on and keeps its world.
TEST_F(HostileTest, ARestoredHullMustBeTheHullItsVerticesMake) {
  v1::SpawnBodiesRequest spawn;
  v1::BodySpec* rock = spawn.add_bodies();
  for (double x : {-1.0, 1.0})
    for (double y : {-1.0, 1.0})
      for (double z : {-1.0, 1.0})
        for (double p : {x * 0.5, y * 0.7, z * 0.9 + 10})
          rock->mutable_shape()->mutable_hull()->add_points(p);
  rock->mutable_shape()->mutable_hull()->add_points(0);
  rock->mutable_shape()->mutable_hull()->add_points(0);
  rock->mutable_shape()->mutable_hull()->add_points(11);  // a ninth point: a roof
  rock->set_mass(3);
  grpc::ClientContext spawn_context;
  v1::SpawnBodiesResponse spawned;
  ASSERT_TRUE(stub_->SpawnBodies(&spawn_context, spawn, &spawned).ok());
  const std::string good = snapshot();
  pb::WorldSnapshot crafted = decoded(good);
  // The roof's vertex, (0, 0, 11) less the centre of mass, is stored as three doubles; its z,
  // the largest vertex z of the hull, moved 1e4 m off its faces.
  std::string& engine = *crafted.mutable_engine_state();
  const World world = World::from_state(WorldSettings{}, engine).value();
  const BodyView hull = world.body(world.id_at(world.slot_count() - 1));
  ASSERT_EQ(hull.shape().type(), ShapeType::kHull);
  const Vec3 roof = hull.shape().support(Vec3(0, 0, 1));
  std::string pattern(24, '\0');
  std::memcpy(pattern.data(), roof.data(), 24);
  const std::size_t at = engine.find(pattern);
  ASSERT_NE(at, std::string::npos);
  const double moved = roof.z() + 1e4;
  std::memcpy(engine.data() + at + 16, &moved, 8);
  const grpc::Status status = restore(crafted.SerializeAsString());
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(status.error_message().find("polyhedron."), std::string::npos)
      << status.error_message();
  EXPECT_EQ(snapshot(), good);
  EXPECT_TRUE(restore(good).ok());
}

// Issue 31 (3, 9): scenes are counted, ground included, before they are parsed or built.
TEST_F(HostileTest, ScenesAreCountedBeforeTheyAreParsedOrBuilt) {
  const std::string before = snapshot();
  auto load = [&](const v1::LoadSceneRequest& request) {
    grpc::ClientContext context;
    v1::LoadSceneResponse response;
    return stub_->LoadScene(&context, request, &response);
  };
  v1::LoadSceneRequest json;
  std::string bodies;
  for (std::size_t i = 0; i <= kMaxBodies; ++i)
    bodies += std::string(i == 0 ? "" : ",") + R"({"shape": "sphere", "radius": 0.5})";
  json.set_scene_json(R"({"bodies": [)" + bodies + "]}");
  const grpc::Status many = load(json);
  EXPECT_EQ(many.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_NE(many.error_message().find("scene_json: bodies: 101 bodies, more than the 100"),
            std::string::npos)
      << many.error_message();

  v1::LoadSceneRequest pile;
  pile.set_builtin("pile:100");  // 101 bodies with the ground
  const grpc::Status counted = load(pile);
  EXPECT_EQ(counted.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(counted.error_message().find("builtin: scene 'pile:100': 101 bodies with the ground"),
            std::string::npos)
      << counted.error_message();
  pile.set_builtin("pile");  // 1001 bodies by default
  EXPECT_EQ(load(pile).error_code(), grpc::StatusCode::INVALID_ARGUMENT);

  v1::LoadSceneRequest long_name;
  long_name.set_builtin(std::string(100000, 'x'));
  const grpc::Status named = load(long_name);
  EXPECT_EQ(named.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_LT(named.error_message().size(), 400u);
  EXPECT_NE(named.error_message().find("(100000 characters)"), std::string::npos);
  EXPECT_EQ(snapshot(), before);

  pile.set_builtin("pile:99");
  EXPECT_TRUE(load(pile).ok());
}

// Issue 31 (10): a step of 5e-324 s never advanced time; a rate of 1e-300 Hz sent no frame.
TEST_F(HostileTest, StepsAndRatesTooSmallToMeanAnythingAreRefused) {
  for (double dt : {5e-324, 1e-300, 1e-9}) {
    v1::ControlRequest request;
    request.mutable_settings()->set_dt(dt);
    grpc::ClientContext context;
    v1::ControlResponse response;
    const grpc::Status status = stub_->Control(&context, request, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << dt;
    EXPECT_NE(status.error_message().find("at least 1e-06 s"), std::string::npos)
        << status.error_message();
  }
  {
    v1::StreamFramesRequest request;
    request.set_max_rate(1e-300);
    grpc::ClientContext context;
    auto reader = stub_->StreamFrames(&context, request);
    v1::Frame frame;
    EXPECT_FALSE(reader->Read(&frame));
    EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  }
  // At the lowest rate allowed the first frame, which describes every body, still comes at once.
  v1::StreamFramesRequest request;
  request.set_max_rate(kMinStreamRate);
  grpc::ClientContext context;
  auto reader = stub_->StreamFrames(&context, request);
  v1::Frame frame;
  ASSERT_TRUE(reader->Read(&frame));
  EXPECT_EQ(frame.added_size(), 9);
  context.TryCancel();
  reader->Finish();
}

TEST(WireScan, CountsEntriesAndTheParsedSizeWithoutParsing) {
  const google::protobuf::Descriptor& spawn = *v1::SpawnBodiesRequest::descriptor();
  std::string empties;
  for (int i = 0; i < 1000; ++i)
    empties += std::string("\x0a\x00", 2);
  Result<WireScan> scan = scan_wire(empties, spawn, 1u << 30, 0);
  ASSERT_TRUE(scan) << scan.error();
  EXPECT_EQ(scan.value().top_entries, 1000u);
  // 2 bytes on the wire, a whole BodySpec in memory: more than 50 times the wire size.
  EXPECT_GT(scan.value().parsed_bytes, 50u * empties.size());
  EXPECT_EQ(scan_wire(empties, spawn, parsed_bound(0) / 1000, 0).status().code(),
            StatusCode::kResourceExhausted);
  EXPECT_EQ(scan_wire(empties, spawn, 1u << 30, 999).status().code(),
            StatusCode::kResourceExhausted);

  // Packed ids: one entry per varint, whatever its length.
  v1::GetBodiesRequest ids;
  for (std::uint64_t id : {1ull, 300ull, 1ull << 40, 7ull})
    ids.add_ids(id);
  scan = scan_wire(ids.SerializeAsString(), *v1::GetBodiesRequest::descriptor(), 1u << 20, 0);
  ASSERT_TRUE(scan) << scan.error();
  EXPECT_EQ(scan.value().top_entries, 4u);

  // A real request scans as within a few times its size.
  v1::SpawnBodiesRequest boxes;
  for (int i = 0; i < 100; ++i) {
    v1::BodySpec* box = boxes.add_bodies();
    box->mutable_shape()->mutable_box()->mutable_size()->set_x(1);
    box->mutable_position()->set_z(i);
  }
  const std::string bytes = boxes.SerializeAsString();
  scan = scan_wire(bytes, spawn, 1u << 30, 0);
  ASSERT_TRUE(scan);
  EXPECT_LT(scan.value().parsed_bytes, parsed_bound(bytes.size()));

  // Not a message: a length past the end, a stray end of group.
  EXPECT_FALSE(scan_wire(std::string("\x0a\x05\x00", 3), spawn, 1u << 20, 0));
  EXPECT_FALSE(scan_wire(std::string("\x0c", 1), spawn, 1u << 20, 0));
}

}  // namespace
}  // namespace tumble::server
