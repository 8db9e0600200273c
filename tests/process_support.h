// Helpers for tests that run our programs as processes: the server on a port of the system's
// choosing, commands with their output, a temporary folder.
#pragma once

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace tumble::testing {

// The server process; killed if a failed assertion leaves the test before it stopped it.
struct Server {
  pid_t pid = -1;
  FILE* out = nullptr;
  bool reaped = false;
  std::string address;  // read from its banner

  ~Server() {
    if (pid > 0 && !reaped) {
      kill(pid, SIGKILL);
      waitpid(pid, nullptr, 0);
    }
    if (out != nullptr) fclose(out);
  }

  // Starts the server with its stdout on a pipe and reads the address it listens on.
  void start(std::vector<std::string> args = {}, std::string listen = "127.0.0.1:0") {
    int fds[2];
    ASSERT_EQ(pipe(fds), 0);
    args.insert(args.begin(),
                {TUMBLE_SERVER_BINARY, "--listen", listen, "--real-time-factor", "0"});
    pid = fork();
    if (pid == 0) {
      dup2(fds[1], STDOUT_FILENO);
      close(fds[0]);
      close(fds[1]);
      std::vector<char*> argv;
      for (std::string& arg : args)
        argv.push_back(arg.data());
      argv.push_back(nullptr);
      execv(TUMBLE_SERVER_BINARY, argv.data());
      _exit(127);
    }
    close(fds[1]);
    out = fdopen(fds[0], "r");
    char line[256] = {};
    ASSERT_NE(fgets(line, sizeof line, out), nullptr);
    const std::string banner = line;
    const auto at = banner.find("listening on ");
    ASSERT_NE(at, std::string::npos) << banner;
    address = banner.substr(at + 13);
    address.erase(address.find_first_of(" \n"));
  }

  // SIGTERM, then the exit status and the last line it printed.
  void stop(int* exit_code, std::string* last_line) {
    ASSERT_EQ(kill(pid, SIGTERM), 0);
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    reaped = true;
    // A server ended by a signal let one of its threads take SIGTERM's default action
    // (EveryThreadBlocksTheStopSignals); say which signal.
    ASSERT_TRUE(WIFEXITED(status))
        << "ended by signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    *exit_code = WEXITSTATUS(status);
    char line[256] = {};
    if (fgets(line, sizeof line, out) != nullptr) *last_line = line;
  }
};

struct Output {
  int code = -1;
  std::string text;  // stdout and stderr
};

Output run(const std::string& command) {
  Output result;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return result;
  char buffer[4096];
  std::size_t n;
  while ((n = fread(buffer, 1, sizeof buffer, pipe)) > 0)
    result.text.append(buffer, n);
  const int status = pclose(pipe);
  result.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

// A fresh directory for one test's files, removed afterwards.
struct TempDir {
  std::filesystem::path path;
  TempDir() {
    char name[] = "/tmp/tumble-test-XXXXXX";
    path = mkdtemp(name);
  }
  ~TempDir() { std::filesystem::remove_all(path); }
  std::string operator/(const std::string& file) const { return (path / file).string(); }
};

}  // namespace tumble::testing
