// tumble-server as its own process on loopback: it starts on a port of the system's choosing,
// answers and streams, serves TLS when given a certificate, refuses oversized requests, and stops
// cleanly on SIGTERM (open streams end with OK). The `tumble` CLI drives it as a user would.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "process_support.h"
#include "tumble/v1/world.grpc.pb.h"

namespace {

using namespace tumble::testing;

namespace fs = std::filesystem;

std::string cli(const Server& server) {
  return std::string(TUMBLE_CLI_BINARY) + " --server " + server.address + " ";
}

std::unique_ptr<tumble::v1::World::Stub> connect(const std::string& address) {
  auto channel = grpc::CreateChannel(address, grpc::InsecureChannelCredentials());
  EXPECT_TRUE(
      channel->WaitForConnected(std::chrono::system_clock::now() + std::chrono::seconds(10)));
  return tumble::v1::World::NewStub(channel);
}

// The server's answer to GetInfo; false when the call failed.
bool get_info(tumble::v1::World::Stub& stub, tumble::v1::GetInfoResponse* info) {
  grpc::ClientContext context;
  return stub.GetInfo(&context, {}, info).ok();
}

TEST(ServerProcess, ServesOverLoopbackAndStopsOnSigterm) {
  Server server;
  ASSERT_NO_FATAL_FAILURE(server.start());
  auto stub = connect(server.address);
  {
    tumble::v1::GetInfoResponse info;
    ASSERT_TRUE(get_info(*stub, &info));
    EXPECT_EQ(info.body_count(), 51u);  // the default scene
  }
  {  // the command-line client: spawn a box, then one frame as a JSON line that holds it
    const Output spawned = run(cli(server) + "spawn box --size 1,1,1 --mass 2 --pos 0,0,5");
    ASSERT_EQ(spawned.code, 0) << spawned.text;
    const Output stream = run(cli(server) + "stream --format jsonl --frames 1");
    EXPECT_EQ(stream.code, 0);
    EXPECT_EQ(stream.text.rfind("{", 0), 0u);
    const std::string id = spawned.text.substr(0, spawned.text.find('\n'));
    EXPECT_NE(stream.text.find("\"id\":" + id), std::string::npos) << id;
    const Output bad = run(cli(server) + "spawn sphere --radius -1");
    EXPECT_NE(bad.text.find("shape.sphere.radius"), std::string::npos) << bad.text;
    EXPECT_NE(bad.code, 0);
  }
  // A stream open at shutdown ends with OK after its frames, not with an error.
  grpc::ClientContext context;
  auto reader = stub->StreamFrames(&context, {});
  tumble::v1::Frame frame;
  ASSERT_TRUE(reader->Read(&frame));
  EXPECT_EQ(frame.added_size(), 52);
  int code = -1;
  std::string last;
  server.stop(&code, &last);
  EXPECT_EQ(code, 0);
  EXPECT_NE(last.find("stopped at step"), std::string::npos) << last;
  while (reader->Read(&frame)) {
  }
  EXPECT_TRUE(reader->Finish().ok());
}

// The stop signals are meant for the main thread's sigwait. A thread that does not block them
// (one started before the mask, as gRPC starts its own when credentials are made) would take
// SIGTERM's default action and kill the server instead of stopping it: CI saw that race once.
TEST(ServerProcess, EveryThreadBlocksTheStopSignals) {
  Server server;
  ASSERT_NO_FATAL_FAILURE(server.start());
  tumble::v1::GetInfoResponse info;
  ASSERT_TRUE(get_info(*connect(server.address), &info));  // a call served: the server is up
  const unsigned long long stop_bits = (1ull << (SIGINT - 1)) | (1ull << (SIGTERM - 1));
  int threads = 0;
  for (const auto& task : fs::directory_iterator("/proc/" + std::to_string(server.pid) + "/task")) {
    // The main thread waits in sigwait, which unblocks the awaited signals while it waits.
    if (task.path().filename() == std::to_string(server.pid)) continue;
    std::ifstream status(task.path() / "status");
    std::string line;
    while (std::getline(status, line))
      if (line.rfind("SigBlk:", 0) == 0) {
        const unsigned long long blocked = std::stoull(line.substr(7), nullptr, 16);
        EXPECT_EQ(blocked & stop_bits, stop_bits)
            << "thread " << task.path().filename() << ": " << line;
        ++threads;
      }
  }
  EXPECT_GT(threads, 1);
  int code = -1;
  std::string last;
  server.stop(&code, &last);
  EXPECT_EQ(code, 0);
}

TEST(ServerProcess, CliCommandsHealthSnapshotRecordAndReplay) {
  Server server;
  ASSERT_NO_FATAL_FAILURE(server.start({"--paused"}));
  const std::string tumble = cli(server);
  TempDir dir;
  for (const char* command :
       {"info",   "health", "spawn", "spawn-scene", "remove",        "bodies",  "play",
        "pause",  "reset",  "step",  "set",         "snapshot",      "restore", "stream",
        "record", "replay", "joint", "joints",      "remove-joints", "drive"}) {
    const Output help = run(tumble + command + " --help");
    EXPECT_EQ(help.code, 0) << command;
    EXPECT_NE(help.text.find("Usage"), std::string::npos) << command << ": " << help.text;
  }
  const Output health = run(tumble + "health");
  EXPECT_EQ(health.code, 0) << health.text;
  EXPECT_EQ(health.text, "SERVING\n");

  const Output set = run(tumble + "set --dt 0.01 --solver soft --gravity 0,0,-5");
  ASSERT_EQ(set.code, 0) << set.text;
  EXPECT_NE(set.text.find("\"dt\":0.01"), std::string::npos) << set.text;
  EXPECT_NE(run(tumble + "set --dt -1").code, 0);
  const Output sweeps = run(tumble + "set --iterations 20 --joint-position-passes 2");
  ASSERT_EQ(sweeps.code, 0) << sweeps.text;
  EXPECT_NE(sweeps.text.find("\"iterations\":20"), std::string::npos) << sweeps.text;
  EXPECT_NE(sweeps.text.find("\"joint_position_passes\":2"), std::string::npos) << sweeps.text;
  const Output too_many = run(tumble + "set --joint-position-passes 1001");
  EXPECT_NE(too_many.code, 0);
  EXPECT_NE(too_many.text.find("joint_position_passes"), std::string::npos) << too_many.text;

  ASSERT_EQ(run(tumble + "step 30").code, 0);
  const Output saved = run(tumble + "snapshot " + dir / "world.snapshot");
  ASSERT_EQ(saved.code, 0) << saved.text;
  const Output before = run(tumble + "bodies");
  ASSERT_EQ(before.code, 0);
  EXPECT_EQ(std::count(before.text.begin(), before.text.end(), '\n'), 51);

  // Record 5 frames of the world running in real time; replay them without the server.
  ASSERT_EQ(run(tumble + "set --real-time-factor 1").code, 0);
  ASSERT_EQ(run(tumble + "play").code, 0);
  const Output recorded = run(tumble + "record " + dir / "run.rec" + " --frames 5");
  ASSERT_EQ(recorded.code, 0) << recorded.text;
  EXPECT_NE(recorded.text.find("recorded 5 frames"), std::string::npos) << recorded.text;
  ASSERT_EQ(run(tumble + "pause").code, 0);
  const Output replay = run(std::string(TUMBLE_CLI_BINARY) + " replay " + dir / "run.rec");
  ASSERT_EQ(replay.code, 0) << replay.text;
  EXPECT_EQ(std::count(replay.text.begin(), replay.text.end(), '\n'), 5) << replay.text;
  EXPECT_NE(replay.text.find("\"added\""), std::string::npos);  // the first frame describes all
  const Output csv =
      run(std::string(TUMBLE_CLI_BINARY) + " replay --format csv " + dir / "run.rec");
  EXPECT_EQ(std::count(csv.text.begin(), csv.text.end(), '\n'), 1 + 5 * 51);
  // A recording cut short (here, in its footer) replays the whole frames, says so and fails.
  fs::resize_file(dir / "run.rec", fs::file_size(dir / "run.rec") - 10);
  const Output cut = run(std::string(TUMBLE_CLI_BINARY) + " replay " + dir / "run.rec");
  EXPECT_NE(cut.code, 0);
  EXPECT_EQ(std::count(cut.text.begin(), cut.text.end(), '\n'), 6);  // 5 frames and the error
  EXPECT_NE(cut.text.find("(frame 6)"), std::string::npos) << cut.text;
  EXPECT_NE(cut.text.find("cut short"), std::string::npos) << cut.text;
  // CSV has a row per body: asking it for contacts or statistics is refused, by name.
  for (const char* extra : {"--contacts", "--stats"}) {
    const Output refused_csv = run(tumble + "stream --format csv --frames 1 " + extra);
    EXPECT_NE(refused_csv.code, 0) << extra;
    EXPECT_NE(refused_csv.text.find("--format jsonl"), std::string::npos) << refused_csv.text;
  }
  const Output with_stats = run(tumble + "stream --frames 1 --stats");
  ASSERT_EQ(with_stats.code, 0) << with_stats.text;
  EXPECT_NE(with_stats.text.find("\"solver_bodies\""), std::string::npos) << with_stats.text;
  const Output garbage = run(std::string(TUMBLE_CLI_BINARY) + " replay " + dir / "world.snapshot");
  EXPECT_NE(garbage.code, 0);
  EXPECT_NE(garbage.text.find("not a tumble recording"), std::string::npos) << garbage.text;

  // Back to step 30 exactly as it was.
  const Output restored = run(tumble + "restore " + dir / "world.snapshot");
  ASSERT_EQ(restored.code, 0) << restored.text;
  EXPECT_EQ(run(tumble + "bodies").text, before.text);
  const Output refused = run(tumble + "restore " + dir / "run.rec");
  EXPECT_NE(refused.code, 0);
  EXPECT_NE(refused.text.find("state"), std::string::npos) << refused.text;
}

TEST(ServerProcess, CliJoinsDrivesReadsAndRemovesJoints) {
  Server server;
  ASSERT_NO_FATAL_FAILURE(server.start({"--paused"}));
  const std::string tumble = cli(server);
  const Output spawned = run(tumble + "spawn box --size 1,1,0.2 --mass 1 --pos 0,0,20");
  ASSERT_EQ(spawned.code, 0) << spawned.text;
  const std::string body = spawned.text.substr(0, spawned.text.find('\n'));
  const Output made =
      run(tumble + "joint hinge " + body + " --anchor 0,0,20 --axis 0,0,1 --motor 2,100");
  ASSERT_EQ(made.code, 0) << made.text;
  const std::string joint = made.text.substr(0, made.text.find('\n'));
  EXPECT_EQ(nlohmann::json::parse(run(tumble + "info").text)["joints"], 1);
  ASSERT_EQ(run(tumble + "step 60").code, 0);
  const Output read = run(tumble + "joints " + joint);
  ASSERT_EQ(read.code, 0) << read.text;
  const nlohmann::json state = nlohmann::json::parse(read.text);
  EXPECT_EQ(state["kind"], "hinge");
  EXPECT_NEAR(state["speed"].get<double>(), 2, 1e-9);
  ASSERT_EQ(run(tumble + "drive " + joint + " --motor -1,100").code, 0);
  ASSERT_EQ(run(tumble + "step 30").code, 0);
  EXPECT_NEAR(nlohmann::json::parse(run(tumble + "joints").text)["speed"].get<double>(), -1, 1e-9);
  const Output refused = run(tumble + "joint ball " + body + " --anchor 0,0,20 --motor 1,1");
  EXPECT_NE(refused.code, 0);
  EXPECT_NE(refused.text.find("joints[0].motor: only hinges and sliders"), std::string::npos)
      << refused.text;
  ASSERT_EQ(run(tumble + "remove-joints " + joint).code, 0);
  EXPECT_EQ(run(tumble + "joints").text, "");
  EXPECT_NE(run(tumble + "remove-joints " + joint).code, 0);  // gone
}

TEST(ServerProcess, CliSpawnsAndSteersAKinematicBody) {
  Server server;
  ASSERT_NO_FATAL_FAILURE(server.start({"--paused"}));
  const std::string tumble = cli(server);
  const Output spawned =
      run(tumble + "spawn box --size 2,2,0.2 --kinematic --linear-velocity 1,0,0 --pos 0,0,1");
  ASSERT_EQ(spawned.code, 0) << spawned.text;
  const std::string deck = spawned.text.substr(0, spawned.text.find('\n'));
  ASSERT_EQ(run(tumble + "step 60").code, 0);
  nlohmann::json state = nlohmann::json::parse(run(tumble + "bodies " + deck).text);
  EXPECT_EQ(state["kinematic"], true);
  EXPECT_NEAR(state["p"][0].get<double>(), 1, 1e-12);  // x0 + v t, exactly
  EXPECT_NEAR(state["p"][2].get<double>(), 1, 1e-12);  // no gravity
  ASSERT_EQ(run(tumble + "set-state " + deck + " --linear-velocity 0,0,0").code, 0);
  ASSERT_EQ(run(tumble + "step 60").code, 0);
  state = nlohmann::json::parse(run(tumble + "bodies " + deck).text);
  EXPECT_NEAR(state["p"][0].get<double>(), 1, 1e-12);
  const Output both = run(tumble + "spawn box --size 1,1,1 --kinematic --static");
  EXPECT_NE(both.code, 0);
  EXPECT_NE(both.text.find("excludes"), std::string::npos) << both.text;
  const Output pushed = run(tumble + "set-state " + deck + " --force 1,0,0");
  EXPECT_NE(pushed.code, 0);
  EXPECT_NE(pushed.text.find("force: a kinematic body moves only by the velocity given it"),
            std::string::npos)
      << pushed.text;
}

TEST(ServerProcess, CliCastsAShape) {
  Server server;
  ASSERT_NO_FATAL_FAILURE(server.start({"--paused"}));
  const std::string tumble = cli(server);
  // Far from the default scene's bodies.
  const Output spawned = run(tumble + "spawn box --size 1,1,1 --static --pos 100,0,0.5");
  ASSERT_EQ(spawned.code, 0) << spawned.text;
  const std::string cube = spawned.text.substr(0, spawned.text.find('\n'));
  const Output hit =
      run(tumble + "cast sphere --radius 0.25 --pos 95,0,0.5 --translation 10,0,0");
  ASSERT_EQ(hit.code, 0) << hit.text;
  const nlohmann::json found = nlohmann::json::parse(hit.text);
  EXPECT_EQ(found["hit"], true);
  EXPECT_EQ(std::to_string(found["id"].get<std::uint64_t>()), cube);
  EXPECT_NEAR(found["fraction"].get<double>() * 10, 4.25, 1e-6);
  EXPECT_NEAR(found["normal"][0].get<double>(), -1, 1e-9);
  const Output miss = run(tumble + "cast box --size 1,1,1 --pos 95,5,0.6 --by 10,0,0");
  EXPECT_EQ(nlohmann::json::parse(miss.text)["hit"], false) << miss.text;
  const Output refused = run(tumble + "cast sphere --radius -1 --translation 1,0,0");
  EXPECT_NE(refused.code, 0);
  EXPECT_NE(refused.text.find("shape_casts[0].shape.sphere.radius"), std::string::npos) << refused.text;
}

// Terrain from a text file of heights: spawned static, seen by a ray down onto it; a ragged file is
// refused naming its line.
TEST(ServerProcess, CliSpawnsAHeightfieldFromAFile) {
  Server server;
  ASSERT_NO_FATAL_FAILURE(server.start({"--paused"}));
  const std::string tumble = cli(server);
  TempDir dir;
  // Three rows along x of four samples: a slope rising 0.5 m per 1 m sample along y.
  std::ofstream(dir / "hills.txt") << "# y = -1\n0 0 0 0\n0.5, 0.5, 0.5, 0.5\n1 1 1 1\n";
  const Output spawned = run(tumble + "spawn heightfield --heights " + (dir / "hills.txt") +
                             " --spacing 1,1 --pos 100,0,0");
  ASSERT_EQ(spawned.code, 0) << spawned.text;
  const std::string field = spawned.text.substr(0, spawned.text.find('\n'));
  const Output bodies = run(tumble + "bodies " + field);
  ASSERT_EQ(bodies.code, 0) << bodies.text;
  EXPECT_NE(bodies.text.find("\"static\":true"), std::string::npos) << bodies.text;
  const Output hit = run(tumble + "ray --from 100.2,0.5,5 --dir 0,0,-1");
  ASSERT_EQ(hit.code, 0) << hit.text;
  EXPECT_NE(hit.text.find(field), std::string::npos) << hit.text;
  std::ofstream(dir / "ragged.txt") << "0 0 0\n0 0\n";
  const Output refused = run(tumble + "spawn heightfield --heights " + (dir / "ragged.txt"));
  EXPECT_NE(refused.code, 0);
  EXPECT_NE(refused.text.find("ragged.txt:2: 2 heights, the first row has 3"), std::string::npos)
      << refused.text;
}

TEST(ServerProcess, CliSpawnsAMeshFromAFile) {
  Server server;
  ASSERT_NO_FATAL_FAILURE(server.start({"--paused"}));
  const std::string tumble = cli(server);
  TempDir dir;
  // A 2 x 2 m floor in cm, one quad the reader splits into two triangles.
  std::ofstream(dir / "floor.obj") << "v -100 -100 0\nv 100 -100 0\nv 100 100 0\nv -100 100 0\n"
                                      "f 1 2 3 4\n";
  const Output spawned =
      run(tumble + "spawn mesh --file " + (dir / "floor.obj") + " --scale 0.01 --pos 100,0,1");
  ASSERT_EQ(spawned.code, 0) << spawned.text;
  const std::string mesh = spawned.text.substr(0, spawned.text.find('\n'));
  const Output bodies = run(tumble + "bodies " + mesh);
  ASSERT_EQ(bodies.code, 0) << bodies.text;
  EXPECT_NE(bodies.text.find("\"static\":true"), std::string::npos) << bodies.text;
  const Output hit = run(tumble + "ray --from 100.2,0.5,5 --dir 0,0,-1");
  ASSERT_EQ(hit.code, 0) << hit.text;
  EXPECT_NE(hit.text.find(mesh), std::string::npos) << hit.text;
  // A file of no triangles, and triangles in a line, are refused naming what is wrong.
  std::ofstream(dir / "points.obj") << "v 0 0 0\nv 1 0 0\n";
  const Output empty = run(tumble + "spawn mesh --file " + (dir / "points.obj"));
  EXPECT_NE(empty.code, 0);
  EXPECT_NE(empty.text.find("points.obj"), std::string::npos) << empty.text;
  const Output missing = run(tumble + "spawn mesh");
  EXPECT_NE(missing.code, 0);
  EXPECT_NE(missing.text.find("--file: required for a mesh"), std::string::npos) << missing.text;
}

TEST(ServerProcess, CliSpawnsACompoundOfParts) {
  Server server;
  ASSERT_NO_FATAL_FAILURE(server.start({"--paused"}));
  const std::string tumble = cli(server);
  // A dumbbell far from the default scene: two balls on a bar turned along y.
  const Output spawned = run(tumble +
                             "spawn compound --part sphere:0.2@0,-0.5,0 --part sphere:0.2@0,0.5,0 "
                             "--part capsule:0.05,0.4@0,0,0@0.7071068,0.7071068,0,0 --pos 100,0,5");
  ASSERT_EQ(spawned.code, 0) << spawned.text;
  const std::string id = spawned.text.substr(0, spawned.text.find('\n'));
  // The stream's first frame describes it: its parts, each with its pose.
  const Output described = run(tumble + "stream --frames 1 --ids " + id);
  ASSERT_EQ(described.code, 0) << described.text;
  EXPECT_NE(described.text.find("\"compound\":[{"), std::string::npos) << described.text;
  EXPECT_NE(described.text.find("\"capsule\":[0.05,0.4]"), std::string::npos) << described.text;
  // A ray down through a ball hits the body; one down beside the bar, between the balls, misses.
  const Output hit = run(tumble + "ray --from 100,0.5,8 --dir 0,0,-1");
  ASSERT_EQ(hit.code, 0) << hit.text;
  EXPECT_NE(hit.text.find(id), std::string::npos) << hit.text;
  const Output miss = run(tumble + "ray --from 100.1,0.25,8 --dir 0,0,-1 --max-distance 5");
  ASSERT_EQ(miss.code, 0) << miss.text;
  EXPECT_EQ(miss.text.find(id), std::string::npos) << miss.text;
  // A part that does not parse, and one the server refuses, are named.
  const Output garbled =
      run(tumble + "spawn compound --part sphere:0.2@0,0,0 --part box:1,1@0,0,0");
  EXPECT_NE(garbled.code, 0);
  EXPECT_NE(garbled.text.find("--part[1]"), std::string::npos) << garbled.text;
  const Output refused = run(tumble + "spawn compound --part sphere:-1@0,0,0");
  EXPECT_NE(refused.code, 0);
  EXPECT_NE(refused.text.find("shape.compound.parts[0].shape.sphere.radius"), std::string::npos)
      << refused.text;
  const Output none = run(tumble + "spawn compound");
  EXPECT_NE(none.code, 0);
  EXPECT_NE(none.text.find("--part: a compound needs at least one"), std::string::npos)
      << none.text;
}

// A hull from the CLI: a square pyramid, its apex up, far from the default scene. The stream
// describes it by its hull's vertices; a ray down through the apex's side hits it and one past
// the base misses; overlap and cast take a hull too; points that do not parse, a flat hull and
// points given to a box are named.
TEST(ServerProcess, CliSpawnsAHullOfPoints) {
  Server server;
  ASSERT_NO_FATAL_FAILURE(server.start({"--paused"}));
  const std::string tumble = cli(server);
  const std::string pyramid =
      "--point -0.5,-0.5,0 --point 0.5,-0.5,0 --point 0.5,0.5,0 --point -0.5,0.5,0 "
      "--point 0,0,1 --point 0,0,0.5 ";
  const Output spawned = run(tumble + "spawn hull " + pyramid + "--pos 100,0,5");
  ASSERT_EQ(spawned.code, 0) << spawned.text;
  const std::string id = spawned.text.substr(0, spawned.text.find('\n'));
  const Output described = run(tumble + "stream --frames 1 --ids " + id);
  ASSERT_EQ(described.code, 0) << described.text;
  EXPECT_NE(described.text.find("\"hull\""), std::string::npos) << described.text;
  const Output hit = run(tumble + "ray --from 100.2,0,8 --dir 0,0,-1");
  ASSERT_EQ(hit.code, 0) << hit.text;
  EXPECT_NE(hit.text.find(id), std::string::npos) << hit.text;
  const Output miss = run(tumble + "ray --from 100.6,0,8 --dir 0,0,-1 --max-distance 5");
  ASSERT_EQ(miss.code, 0) << miss.text;
  EXPECT_EQ(miss.text.find(id), std::string::npos) << miss.text;
  const Output overlapping = run(tumble + "overlap hull " + pyramid + "--pos 100,0,5.2");
  ASSERT_EQ(overlapping.code, 0) << overlapping.text;
  EXPECT_NE(overlapping.text.find(id), std::string::npos) << overlapping.text;
  const Output cast = run(tumble + "cast hull " + pyramid + "--pos 100,0,9 --by 0,0,-5");
  ASSERT_EQ(cast.code, 0) << cast.text;
  EXPECT_NE(cast.text.find(id), std::string::npos) << cast.text;
  const Output garbled = run(tumble + "spawn hull --point 0,0,0 --point 1,0");
  EXPECT_NE(garbled.code, 0);
  EXPECT_NE(garbled.text.find("--point[1]: '1,0' is not X,Y,Z"), std::string::npos) << garbled.text;
  const Output flat =
      run(tumble + "spawn hull --point 0,0,0 --point 1,0,0 --point 0,1,0 --point 1,1,0");
  EXPECT_NE(flat.code, 0);
  EXPECT_NE(flat.text.find("shape.hull.points: coplanar or collinear"), std::string::npos)
      << flat.text;
  const Output misplaced = run(tumble + "spawn box --point 0,0,0");
  EXPECT_NE(misplaced.code, 0);
  EXPECT_NE(misplaced.text.find("--point: only a hull has points"), std::string::npos)
      << misplaced.text;
}

// A hull of a mesh file's vertices: a ball of radius 0.5 m in cm, 60 rings of 120 vertices
// (7,082, more than the 1024 a hull may be given): the CLI says it keeps the farthest towards
// 1024 directions, the server builds the hull, a ray 0.49 m off its axis hits it and one 0.51 m
// off misses; overlap takes the file too; a file given to a box, or with points, is refused.
TEST(ServerProcess, CliSpawnsAHullOfAMeshFile) {
  Server server;
  ASSERT_NO_FATAL_FAILURE(server.start({"--paused"}));
  const std::string tumble = cli(server);
  TempDir dir;
  {
    std::ofstream obj(dir / "ball.obj");
    const int rings = 60, around = 120;
    obj << "v 0 0 50\n";
    for (int i = 1; i < rings; ++i)
      for (int j = 0; j < around; ++j) {
        const double polar = std::numbers::pi * i / rings,
                     azimuth = 2 * std::numbers::pi * j / around;
        obj << "v " << 50 * std::sin(polar) * std::cos(azimuth) << ' '
            << 50 * std::sin(polar) * std::sin(azimuth) << ' ' << 50 * std::cos(polar) << '\n';
      }
    obj << "v 0 0 -50\n";
    const int last = 2 + (rings - 1) * around;  // the south pole's index (from 1)
    const auto at = [&](int ring, int j) { return 2 + (ring - 1) * around + j % around; };
    for (int j = 0; j < around; ++j) {
      obj << "f 1 " << at(1, j) << ' ' << at(1, j + 1) << '\n';
      for (int i = 1; i + 1 < rings; ++i)
        obj << "f " << at(i, j) << ' ' << at(i + 1, j) << ' ' << at(i + 1, j + 1) << ' '
            << at(i, j + 1) << '\n';
      obj << "f " << last << ' ' << at(rings - 1, j + 1) << ' ' << at(rings - 1, j) << '\n';
    }
  }
  const std::string ball = "--file " + (dir / "ball.obj") + " --scale 0.01 ";
  const Output spawned = run(tumble + "spawn hull " + ball + "--pos 100,0,5");
  ASSERT_EQ(spawned.code, 0) << spawned.text;
  EXPECT_NE(spawned.text.find("ball.obj: 7082 vertices, more than the 1024 a hull may be given"),
            std::string::npos)
      << spawned.text;
  // The note went to stderr first; the id is the last line.
  std::string body = spawned.text.substr(spawned.text.rfind('\n', spawned.text.size() - 2) + 1);
  if (!body.empty() && body.back() == '\n') body.pop_back();
  ASSERT_FALSE(body.empty());
  const Output hit = run(tumble + "ray --from 100.49,0,8 --dir 0,0,-1");
  ASSERT_EQ(hit.code, 0) << hit.text;
  EXPECT_NE(hit.text.find(body), std::string::npos) << hit.text;
  const Output miss = run(tumble + "ray --from 100.51,0,8 --dir 0,0,-1 --max-distance 5");
  ASSERT_EQ(miss.code, 0) << miss.text;
  EXPECT_EQ(miss.text.find(body), std::string::npos) << miss.text;
  const Output overlapping = run(tumble + "overlap hull " + ball + "--pos 100,0,5.9");
  ASSERT_EQ(overlapping.code, 0) << overlapping.text;
  EXPECT_NE(overlapping.text.find(body), std::string::npos) << overlapping.text;
  const Output boxed = run(tumble + "spawn box " + ball);
  EXPECT_NE(boxed.code, 0);
  EXPECT_NE(boxed.text.find("--file: only a hull or a mesh comes from a file"), std::string::npos)
      << boxed.text;
  const Output both = run(tumble + "spawn hull " + ball + "--point 0,0,0");
  EXPECT_NE(both.code, 0);
  EXPECT_NE(both.text.find("--file: a hull comes from --point or from --file, not both"),
            std::string::npos)
      << both.text;
}

TEST(ServerProcess, OversizedRequestsAreRefusedAndChangeNothing) {
  Server server;
  ASSERT_NO_FATAL_FAILURE(server.start({"--paused", "--max-message-mb", "1"}));
  auto stub = connect(server.address);
  tumble::v1::RestoreRequest request;
  request.set_state(std::string(2 << 20, 'x'));
  grpc::ClientContext context;
  tumble::v1::RestoreResponse response;
  const grpc::Status status = stub->Restore(&context, request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << status.error_message();
  tumble::v1::GetInfoResponse info;
  ASSERT_TRUE(get_info(*stub, &info));
  EXPECT_EQ(info.body_count(), 51u);
}

TEST(ServerProcess, ServesTlsWithACertificate) {
  TempDir dir;
  const Output made =
      run("openssl req -x509 -newkey rsa:2048 -nodes -days 2 -subj /CN=localhost "
          "-addext subjectAltName=DNS:localhost,IP:127.0.0.1 -keyout " +
          dir / "key.pem" + " -out " + dir / "cert.pem");
  ASSERT_EQ(made.code, 0) << made.text;
  Server server;
  ASSERT_NO_FATAL_FAILURE(
      server.start({"--tls-cert", dir / "cert.pem", "--tls-key", dir / "key.pem"}));
  const Output secure = run(cli(server) + "--tls-ca " + dir / "cert.pem" + " info");
  EXPECT_EQ(secure.code, 0) << secure.text;
  EXPECT_NE(secure.text.find("\"bodies\":51"), std::string::npos) << secure.text;
  // A plaintext client gets nothing from a TLS server.
  const Output plain = run("timeout 20 " + cli(server) + "info");
  EXPECT_NE(plain.code, 0) << plain.text;
  // Half a TLS configuration is refused at start.
  const Output half = run(std::string(TUMBLE_SERVER_BINARY) + " --listen 127.0.0.1:0 --tls-cert " +
                          dir / "cert.pem");
  EXPECT_EQ(half.code, 2);
  EXPECT_NE(half.text.find("--tls-key"), std::string::npos) << half.text;
}

}  // namespace
