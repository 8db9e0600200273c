// A world in the caller's process, as Python's tumble.World() holds it: the server's hosted world
// and the server's own request handling (server/world_commands.h), without gRPC, threads or
// pacing. Requests and answers are the tumble.v1 messages' bytes, so the Python side shares every
// conversion and check with its remote client; a script moves between the two by changing how it
// makes its world.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>

#include "catalogue_diff.h"
#include "convert.h"
#include "frame.h"
#include "hosted_world.h"
#include "scenes/scene.h"

namespace tumble::python {

struct LocalLimits {
  std::size_t max_bodies = 100000;  // as tumble-server's --max-bodies
  WorldLimits world;
};

class LocalWorld {
 public:
  // An empty world (no bodies, a step of 1/60 s); `threads`: the step's OpenMP threads (0: all).
  LocalWorld(int threads, const LocalLimits& limits);

  // A tumble.v1.World method by name ("SpawnBodies", "Control", ...): the request's bytes in, the
  // response's bytes out; refused as the server refuses it, changing nothing.
  Result<std::string> call(std::string_view method, std::string_view request);
  // Steps n times with the world's dt; stops at (and reports) a step that failed.
  Status step(std::uint64_t n);

  // The frame of the world as it is now, for one reader who was told `diff`'s bodies before.
  std::string frame(const server::FrameOptions& options, server::CatalogueDiff& diff);
  // The world as it is now (the contacts of the last step, and those asleep).
  std::shared_ptr<const server::FrameData> frame_data();

  server::HostedWorld& hosted() { return hosted_; }
  // Held by every call into this world (tumble._engine takes it): Python threads that share a
  // world take turns, since the GIL is let go while the world steps.
  std::mutex& mutex() { return mutex_; }
  const LocalLimits& limits() const { return limits_; }
  bool running() const { return running_; }

 private:
  Result<std::string> control(std::string_view request);
  Result<std::string> info() const;
  void refresh_catalogue();

  std::mutex mutex_;
  LocalLimits limits_;
  server::HostedWorld hosted_;
  SceneDef scene_;        // what Control's reset goes back to: the last scene loaded
  bool running_ = false;  // play() was called: frames() steps; the world does not run by itself
  double real_time_factor_ = 0;
  std::shared_ptr<const server::Catalogue> catalogue_;
  std::uint64_t catalogue_epoch_ = 0;
};

}  // namespace tumble::python
