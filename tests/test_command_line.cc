// Our programs keep their ecosystem's conventions on the command line, and the CLI has the
// commands a user reaches for: --version, exit status 2 for a usage error, defaults in --help,
// errors that name the environment variable or the file at fault; a second server on a taken
// port fails; health answers by service name; impulses, state changes and sleeping from the CLI;
// a recording without velocities replays as CSV with a header that matches its rows.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

#include <google/protobuf/descriptor.h>
#include <google/protobuf/descriptor.pb.h>
#include <grpcpp/ext/proto_server_reflection_plugin.h>

#include "grpc/health/v1/health.grpc.pb.h"
#include "grpc/reflection/v1/reflection.grpc.pb.h"
#include "process_support.h"

namespace {

using namespace tumble::testing;

std::vector<std::string> programs() {
  std::vector<std::string> all = {TUMBLE_SERVER_BINARY, TUMBLE_CLI_BINARY, TUMBLE_RUN_BINARY};
#ifdef TUMBLE_VIEWER_BINARY
  all.push_back(TUMBLE_VIEWER_BINARY);
#endif
#ifdef TUMBLE_DDS_ECHO_BINARY
  all.push_back(TUMBLE_DDS_ECHO_BINARY);
#endif
  return all;
}

std::string cli(const Server& server) {
  return std::string(TUMBLE_CLI_BINARY) + " --server " + server.address + " ";
}

TEST(CommandLine, EveryProgramPrintsItsVersionAndExitsTwoOnAUsageError) {
  for (const std::string& program : programs()) {
    SCOPED_TRACE(program);
    const Output version = run(program + " --version");
    EXPECT_EQ(version.code, 0) << version.text;
    EXPECT_NE(version.text.find(TUMBLE_VERSION), std::string::npos) << version.text;
    const Output unknown = run(program + " --no-such-flag");
    EXPECT_EQ(unknown.code, 2) << unknown.text;
    EXPECT_NE(unknown.text.find("--no-such-flag"), std::string::npos) << unknown.text;
    const Output help = run(program + " --help");
    EXPECT_EQ(help.code, 0) << help.text;
  }
  // The defaults are in --help: the address a client calls and a server listens on.
  EXPECT_NE(run(std::string(TUMBLE_CLI_BINARY) + " --help").text.find("127.0.0.1:50051"),
            std::string::npos);
  EXPECT_NE(run(std::string(TUMBLE_SERVER_BINARY) + " --help").text.find("127.0.0.1:50051"),
            std::string::npos);
}

TEST(CommandLine, MistakesAreNamedAsWhatTheyAre) {
  const std::string tumble = TUMBLE_CLI_BINARY;
  const Output unknown = run(tumble + " frobnicate");
  EXPECT_EQ(unknown.code, 2);
  EXPECT_NE(unknown.text.find("unknown command 'frobnicate'"), std::string::npos) << unknown.text;
  EXPECT_NE(unknown.text.find("spawn"), std::string::npos) << unknown.text;  // what there is
  const Output none = run(tumble);
  EXPECT_EQ(none.code, 2);
  EXPECT_NE(none.text.find("a command is required"), std::string::npos) << none.text;
  const Output missing = run(tumble + " restore /nonexistent/world.snap");
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.text.find("/nonexistent/world.snap: no such file"), std::string::npos)
      << missing.text;
  // A value from the environment is refused by the variable's name, in a line, not with the
  // largest double written out.
  const Output variable =
      run("TUMBLE_THREADS=abc " + std::string(TUMBLE_SERVER_BINARY) + " --listen 127.0.0.1:0");
  EXPECT_EQ(variable.code, 2);
  EXPECT_NE(variable.text.find("TUMBLE_THREADS=abc"), std::string::npos) << variable.text;
  EXPECT_NE(variable.text.find("not a number"), std::string::npos) << variable.text;
  EXPECT_LT(variable.text.size(), 300u) << variable.text;
  const Output negative = run(std::string(TUMBLE_SERVER_BINARY) + " --threads -2");
  EXPECT_EQ(negative.code, 2);
  EXPECT_NE(negative.text.find("must be 0 or more"), std::string::npos) << negative.text;
  // Each thread of the team is made: a million is refused, not attempted.
  for (const char* program : {TUMBLE_SERVER_BINARY, TUMBLE_RUN_BINARY}) {
    const Output many = run(std::string(program) + " --threads 1000000");
    EXPECT_EQ(many.code, 2) << program;
    EXPECT_NE(many.text.find("not in range 0 to 1024"), std::string::npos) << many.text;
  }
}

// Spinning OpenMP threads collapse a step on a busy machine (passive_wait.h): the programs that
// step a world wait passively unless the user chose otherwise.
TEST(CommandLine, OpenMpThreadsWaitPassivelyUnlessTheUserChose) {
  const std::string run_scene =
      std::string(TUMBLE_RUN_BINARY) + " --standard pile:8 --duration 0.05 --threads 2";
  const Output chosen_for_them = run("env -u OMP_WAIT_POLICY " + run_scene);
  ASSERT_EQ(chosen_for_them.code, 0) << chosen_for_them.text;
  EXPECT_NE(chosen_for_them.text.find("2 threads waiting passive"), std::string::npos)
      << chosen_for_them.text;
  const Output chosen = run("OMP_WAIT_POLICY=active " + run_scene);
  EXPECT_NE(chosen.text.find("2 threads waiting active"), std::string::npos) << chosen.text;
}

#ifdef TUMBLE_DDS_ECHO_BINARY
// With nothing to hear, tumble-dds-echo says so after 5 s (and keeps listening until --timeout),
// instead of waiting in silence.
TEST(CommandLine, DdsEchoSaysWhenNothingArrives) {
  const Output silent = run(std::string(TUMBLE_DDS_ECHO_BINARY) + " --domain 201 --timeout 6");
  EXPECT_EQ(silent.code, 0) << silent.text;
  EXPECT_NE(silent.text.find("nothing received on domain 201 in 5 s"), std::string::npos)
      << silent.text;
}
#endif

TEST(CommandLine, ASecondServerOnATakenPortFailsNamingIt) {
  Server first;
  ASSERT_NO_FATAL_FAILURE(first.start({"--paused"}));
  const Output second = run("timeout 30 " + std::string(TUMBLE_SERVER_BINARY) + " --listen " +
                            first.address + " --paused");
  EXPECT_EQ(second.code, 1) << second.text;
  EXPECT_NE(second.text.find("cannot listen on " + first.address), std::string::npos)
      << second.text;
  EXPECT_NE(second.text.find("address already in use"), std::string::npos) << second.text;
  EXPECT_EQ(second.text.find("listening on"), std::string::npos) << second.text;
  // The first one still answers, alone.
  EXPECT_EQ(run(cli(first) + "health").code, 0);
}

TEST(CommandLine, HealthAnswersByTheServicesName) {
  Server server;
  ASSERT_NO_FATAL_FAILURE(server.start({"--paused"}));
  auto channel = grpc::CreateChannel(server.address, grpc::InsecureChannelCredentials());
  auto health = grpc::health::v1::Health::NewStub(channel);
  for (const char* name : {"", "tumble.v1.World"}) {
    grpc::ClientContext context;
    grpc::health::v1::HealthCheckRequest request;
    request.set_service(name);
    grpc::health::v1::HealthCheckResponse response;
    const grpc::Status status = health->Check(&context, request, &response);
    ASSERT_TRUE(status.ok()) << "'" << name << "': " << status.error_message();
    EXPECT_EQ(response.status(), grpc::health::v1::HealthCheckResponse::SERVING) << name;
  }
}

// Reflection v1 (which newer tools ask for first) answers beside v1alpha, and its messages are
// v1alpha's field for field, so a tool reads both alike.
TEST(CommandLine, ReflectionV1ListsTheServicesAndDescribesTheApi) {
  // A call into gRPC's reflection library, so that the linker keeps it (and its v1alpha
  // descriptors in the pool).
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  const auto* pool = google::protobuf::DescriptorPool::generated_pool();
  for (const char* name :
       {"ServerReflectionRequest", "ExtensionRequest", "ServerReflectionResponse",
        "FileDescriptorResponse", "ExtensionNumberResponse", "ListServiceResponse",
        "ServiceResponse", "ErrorResponse"}) {
    const auto* v1 = pool->FindMessageTypeByName(std::string("grpc.reflection.v1.") + name);
    const auto* alpha = pool->FindMessageTypeByName(std::string("grpc.reflection.v1alpha.") + name);
    ASSERT_NE(v1, nullptr) << name;
    ASSERT_NE(alpha, nullptr) << name;
    ASSERT_EQ(v1->field_count(), alpha->field_count()) << name;
    for (int i = 0; i < v1->field_count(); ++i) {
      const auto* a = v1->field(i);
      const auto* b = alpha->FindFieldByNumber(a->number());
      ASSERT_NE(b, nullptr) << name << "." << a->name();
      EXPECT_EQ(a->name(), b->name());
      EXPECT_EQ(a->type(), b->type()) << name << "." << a->name();
      EXPECT_EQ(a->is_repeated(), b->is_repeated()) << name << "." << a->name();
    }
  }

  Server server;
  ASSERT_NO_FATAL_FAILURE(server.start({"--paused", "--token", "secret"}));
  auto stub = grpc::reflection::v1::ServerReflection::NewStub(
      grpc::CreateChannel(server.address, grpc::InsecureChannelCredentials()));
  grpc::ClientContext context;
  auto stream = stub->ServerReflectionInfo(&context);
  grpc::reflection::v1::ServerReflectionRequest request;
  grpc::reflection::v1::ServerReflectionResponse response;
  request.set_list_services("");
  ASSERT_TRUE(stream->Write(request));
  ASSERT_TRUE(stream->Read(&response));
  std::vector<std::string> services;
  for (const auto& service : response.list_services_response().service())
    services.push_back(service.name());
  EXPECT_NE(std::find(services.begin(), services.end(), "tumble.v1.World"), services.end());
  EXPECT_NE(std::find(services.begin(), services.end(), "grpc.reflection.v1.ServerReflection"),
            services.end());

  request.set_file_containing_symbol("tumble.v1.World.SpawnBodies");
  ASSERT_TRUE(stream->Write(request));
  ASSERT_TRUE(stream->Read(&response));
  const auto& files = response.file_descriptor_response().file_descriptor_proto();
  ASSERT_GE(files.size(), 1);
  google::protobuf::FileDescriptorProto last;
  ASSERT_TRUE(last.ParseFromString(files[files.size() - 1]));  // imports come first
  EXPECT_EQ(last.name(), "tumble/v1/world.proto");

  request.set_file_containing_symbol("tumble.v1.NoSuchThing");
  ASSERT_TRUE(stream->Write(request));
  ASSERT_TRUE(stream->Read(&response));
  EXPECT_EQ(response.error_response().error_code(), grpc::StatusCode::NOT_FOUND);
  stream->WritesDone();
  EXPECT_TRUE(stream->Finish().ok());
}

TEST(CommandLine, ImpulsesStatesAndSleepingFromTheCli) {
  Server server;
  ASSERT_NO_FATAL_FAILURE(server.start({"--paused"}));
  const std::string tumble = cli(server);
  std::vector<std::string> ids;
  for (const char* z : {"0.5", "3"}) {  // far from the default scene's bodies
    const Output made = run(tumble + "spawn box --size 1,1,1 --mass 2 --position 50,50," + z);
    ASSERT_EQ(made.code, 0) << made.text;
    ids.push_back(made.text.substr(0, made.text.find('\n')));
  }
  // Ids by commas, as `stream --ids` takes them.
  const Output two = run(tumble + "bodies " + ids[0] + "," + ids[1]);
  ASSERT_EQ(two.code, 0) << two.text;
  EXPECT_EQ(std::count(two.text.begin(), two.text.end(), '\n'), 2);

  ASSERT_EQ(run(tumble + "impulse " + ids[1] + " --impulse 4,0,0").code, 0);
  const Output pushed = run(tumble + "bodies " + ids[1]);
  EXPECT_NE(pushed.text.find("\"v\":[2.0,0.0,0.0]"), std::string::npos)
      << pushed.text;  // 4 N s / 2 kg
  ASSERT_EQ(
      run(tumble + "set-state " + ids[1] + " --position 55,50,3 --linear-velocity 0,0,0").code, 0);
  const Output moved = run(tumble + "bodies " + ids[1]);
  EXPECT_NE(moved.text.find("\"p\":[55.0,50.0,3.0]"), std::string::npos) << moved.text;
  const Output refused = run(tumble + "impulse 999999 --impulse 1,0,0");
  EXPECT_EQ(refused.code, 1);
  EXPECT_NE(refused.text.find("no body"), std::string::npos) << refused.text;

  // The box on the floor falls asleep and still reports its contacts, carrying m g dt.
  ASSERT_EQ(run(tumble + "step 120").code, 0);
  const Output asleep = run(tumble + "bodies " + ids[0]);
  EXPECT_NE(asleep.text.find("\"asleep\":true"), std::string::npos) << asleep.text;
  const Output frame = run(tumble + "stream --frames 1 --contacts --ids " + ids[0]);
  ASSERT_EQ(frame.code, 0) << frame.text;
  EXPECT_NE(frame.text.find("\"contacts\""), std::string::npos) << frame.text;
  EXPECT_NE(frame.text.find("\"impulse\""), std::string::npos) << frame.text;
  // Sleeping off wakes it.
  const Output off = run(tumble + "set --sleeping off");
  ASSERT_EQ(off.code, 0) << off.text;
  EXPECT_NE(off.text.find("\"sleeping\":false"), std::string::npos) << off.text;
  const Output awake = run(tumble + "bodies " + ids[0]);
  EXPECT_NE(awake.text.find("\"asleep\":false"), std::string::npos) << awake.text;
}

TEST(CommandLine, ACsvReplayWithoutVelocitiesHasTheColumnsOfItsRows) {
  Server server;
  ASSERT_NO_FATAL_FAILURE(server.start());
  TempDir dir;
  const Output recorded = run(cli(server) + "record " + dir / "run.rec" + " --frames 3");
  ASSERT_EQ(recorded.code, 0) << recorded.text;
  for (const char* format : {"csv"}) {
    const Output replay =
        run(std::string(TUMBLE_CLI_BINARY) + " replay --format " + format + " " + dir / "run.rec");
    ASSERT_EQ(replay.code, 0) << replay.text;
    std::istringstream lines(replay.text);
    std::string header, row;
    ASSERT_TRUE(std::getline(lines, header));
    EXPECT_EQ(header, "step,time,id,x,y,z,qw,qx,qy,qz");
    int rows = 0;
    while (std::getline(lines, row)) {
      ++rows;
      EXPECT_EQ(std::count(row.begin(), row.end(), ','),
                std::count(header.begin(), header.end(), ','))
          << row;
    }
    EXPECT_EQ(rows, 3 * 51);
  }
}

}  // namespace
