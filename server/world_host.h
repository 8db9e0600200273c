// The world as the server runs it: one thread owns the World and steps it; every change comes in
// as a command that this thread applies between two steps, so a change is never seen half done;
// after each step one immutable frame is built and offered to every subscriber's mailbox.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <unordered_map>
#include <utility>
#include <vector>

#include "frame.h"
#include "frame_sink.h"
#include "hosted_world.h"
#include "mailbox.h"
#include "physics/world.h"

namespace tumble::server {

using FrameMailbox = Mailbox<FrameData>;

struct HostStatus {
  std::uint64_t step = 0;
  double time = 0;
  std::size_t bodies = 0;
  std::size_t joints = 0;
  bool running = false;
  double dt = 0, real_time_factor = 0;
  StepStats last_step;
  std::size_t subscribers = 0;
  // The world's settings as the last command left them (only commands change them), so that
  // reading them never waits for a step in progress.
  WorldSettings settings;
  // Simulated seconds per wall-clock second over the last second of running (0 before it).
  double achieved_real_time_factor = 0;
  // Paced and unable to keep up: the steps are late by more than kBehindSeconds. Set until the
  // world is on time again; counted once per such episode.
  bool behind = false;
  std::uint64_t times_behind = 0;
};

// How late the paced steps may run before the world counts as behind; past it, the debt is
// forgiven (the pace restarts from now) rather than paid by running flat out.
inline constexpr double kBehindSeconds = 0.25;

// Simulated seconds per wall-clock second when paced; 0 runs flat out.
inline constexpr double kMinRealTimeFactor = 1e-3, kMaxRealTimeFactor = 1e3;
Status check_real_time_factor(double factor);

class WorldHost {
 public:
  // `dt`: s per step; `real_time_factor`: 1 paces simulated time to wall time, 0 runs flat out.
  WorldHost(World world, double dt, double real_time_factor);
  ~WorldHost();  // stops the thread; pending commands are answered with an error
  WorldHost(const WorldHost&) = delete;
  WorldHost& operator=(const WorldHost&) = delete;

  // Runs `change` on the world on the stepping thread, between two steps, and returns its
  // status. A change that fails must leave the world as it found it (the World's own batch
  // operations do). Blocks until applied; subscribers then get a frame showing the change.
  Status apply(std::function<Status(HostedWorld&)> change);
  // Runs `read` between two steps, changing nothing (no frame is published for it).
  void inspect(std::function<void(const HostedWorld&)> read);

  void play();
  void pause();
  // Runs `steps` more steps, then pauses.
  void step(std::uint64_t steps);
  Status set_dt(double dt);
  Status set_real_time_factor(double factor);
  // Waits until the world is paused with no steps left to run, or the timeout passes.
  bool wait_idle(std::chrono::milliseconds timeout);

  // Every frame from now on goes to `sink` too, starting with the newest: nothing is dropped,
  // and the world waits before a step until the sink has room (frame_sink.h). One sink at most;
  // nullptr ends it.
  void record_to(std::shared_ptr<FrameSink> sink);

  std::shared_ptr<FrameMailbox> subscribe();
  void unsubscribe(const std::shared_ptr<FrameMailbox>& mailbox);

  HostStatus status() const;

 private:
  struct Command {
    std::function<Status(HostedWorld&)> change;
    std::promise<Status> done;
    bool read_only = false;
  };
  Status submit(Command command);
  void refresh_catalogue();
  void run();
  void apply_pending();
  // `dt`: the step's (hosted_.dt is read under the lock; a frame is built without it).
  std::shared_ptr<const FrameData> make_frame(double dt);

  HostedWorld hosted_;  // the world by the stepping thread only (commands run there); dt under
                        // the lock
  std::shared_ptr<const Catalogue> catalogue_ = std::make_shared<Catalogue>();
  std::uint64_t catalogue_epoch_ = 0;
  mutable std::mutex mutex_;
  std::condition_variable wake_;  // commands, play, step, stop
  std::condition_variable idle_;
  std::deque<Command> commands_;
  bool running_ = false, stopping_ = false;
  std::uint64_t steps_left_ = 0;
  // A step is being computed (the lock is released meanwhile): the world is still running, and
  // neither status() nor wait_idle() may say otherwise until it is done.
  bool in_step_ = false;
  double real_time_factor_;
  HostStatus status_;
  std::vector<std::shared_ptr<FrameMailbox>> subscribers_;
  std::shared_ptr<FrameSink> sink_;
  // The newest frame: a new subscriber starts from it, even while the world is paused.
  std::shared_ptr<const FrameData> last_frame_;
  void publish(std::shared_ptr<const FrameData> frame);
  std::thread thread_;
};

}  // namespace tumble::server
