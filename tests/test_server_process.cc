// tumble-server as its own process on loopback: it starts on a port of the system's choosing,
// answers and streams, and stops cleanly on SIGTERM.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <string>

#include "tumble/v1/world.grpc.pb.h"

namespace {

// The server process; killed if a failed assertion leaves the test before it stopped it.
struct Child {
  pid_t pid = -1;
  FILE* out = nullptr;
  bool reaped = false;
  ~Child() {
    if (pid > 0 && !reaped) {
      kill(pid, SIGKILL);
      waitpid(pid, nullptr, 0);
    }
    if (out != nullptr) fclose(out);
  }
};

// Starts the server with its stdout on a pipe.
void start_server(Child* child) {
  int fds[2];
  if (pipe(fds) != 0) return;
  const pid_t pid = fork();
  if (pid == 0) {
    dup2(fds[1], STDOUT_FILENO);
    close(fds[0]);
    close(fds[1]);
    execl(TUMBLE_SERVER_BINARY, TUMBLE_SERVER_BINARY, "--listen", "127.0.0.1:0",
          "--real-time-factor", "0", static_cast<char*>(nullptr));
    _exit(127);
  }
  close(fds[1]);
  child->pid = pid;
  child->out = fdopen(fds[0], "r");
}

TEST(ServerProcess, ServesOverLoopbackAndStopsOnSigterm) {
  Child server;
  start_server(&server);
  ASSERT_GT(server.pid, 0);
  char line[256] = {};
  ASSERT_NE(fgets(line, sizeof line, server.out), nullptr);
  const std::string banner = line;
  const auto at = banner.find("listening on ");
  ASSERT_NE(at, std::string::npos) << banner;
  std::string address = banner.substr(at + 13);
  address.erase(address.find_last_not_of("\n") + 1);

  auto channel = grpc::CreateChannel(address, grpc::InsecureChannelCredentials());
  ASSERT_TRUE(
      channel->WaitForConnected(std::chrono::system_clock::now() + std::chrono::seconds(10)));
  auto stub = tumble::v1::World::NewStub(channel);
  {
    grpc::ClientContext context;
    tumble::v1::GetInfoResponse info;
    ASSERT_TRUE(stub->GetInfo(&context, {}, &info).ok());
    EXPECT_EQ(info.body_count(), 51u);  // the default scene
  }
  {
    grpc::ClientContext context;
    tumble::v1::StreamFramesRequest request;
    auto reader = stub->StreamFrames(&context, request);
    tumble::v1::Frame frame;
    ASSERT_TRUE(reader->Read(&frame));
    EXPECT_EQ(frame.ids_size(), 51);
    EXPECT_EQ(frame.added_size(), 51);
    context.TryCancel();
    reader->Finish();
  }
  {  // the command-line client: spawn a box, then one frame as a JSON line that holds it
    const std::string cli = std::string(TUMBLE_CLI_BINARY) + " --server " + address + " ";
    FILE* spawn = popen((cli + "spawn box --size 1,1,1 --mass 2 --pos 0,0,5").c_str(), "r");
    ASSERT_NE(spawn, nullptr);
    char id[64] = {};
    ASSERT_NE(fgets(id, sizeof id, spawn), nullptr);
    EXPECT_EQ(pclose(spawn), 0);
    FILE* stream = popen((cli + "stream --format jsonl --frames 1").c_str(), "r");
    ASSERT_NE(stream, nullptr);
    std::string json;
    char buffer[4096];
    while (fgets(buffer, sizeof buffer, stream) != nullptr)
      json += buffer;
    EXPECT_EQ(pclose(stream), 0);
    EXPECT_EQ(json.rfind("{", 0), 0u);
    const std::string spawned = std::string("\"id\":") + std::string(id, strcspn(id, "\n"));
    EXPECT_NE(json.find(spawned), std::string::npos) << spawned;
    FILE* bad = popen((cli + "spawn sphere --radius -1 2>&1").c_str(), "r");
    ASSERT_NE(bad, nullptr);
    ASSERT_NE(fgets(buffer, sizeof buffer, bad), nullptr);
    EXPECT_NE(std::string(buffer).find("shape.sphere.radius"), std::string::npos) << buffer;
    EXPECT_NE(pclose(bad), 0);
  }
  ASSERT_EQ(kill(server.pid, SIGTERM), 0);
  int status = 0;
  ASSERT_EQ(waitpid(server.pid, &status, 0), server.pid);
  server.reaped = true;
  EXPECT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  ASSERT_NE(fgets(line, sizeof line, server.out), nullptr);
  EXPECT_NE(std::string(line).find("stopped at step"), std::string::npos) << line;
}

}  // namespace
