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

#include "body_ids.h"
#include "mailbox.h"
#include "physics/world.h"

namespace tumble::server {

// What a viewer needs to draw a body, kept while the body lives.
struct BodyLook {
  Shape shape;  // in the body's frame (origin at the centre of mass)
  BodyType type = BodyType::kDynamic;
  double mass = 0;           // kg; 0 for static bodies
  std::uint32_t colour = 0;  // 0xRRGGBBAA; 0 lets the viewer choose
};
// Every live body's look by wire id. Shared by frames until the set of bodies changes.
using Catalogue = std::unordered_map<std::uint64_t, BodyLook>;

// The world and what the server keeps beside it. Only the stepping thread touches it: commands
// run there.
struct HostedWorld {
  World world;
  double dt = 1.0 / 60;                // s per step
  std::vector<std::uint32_t> colours;  // by slot, 0xRRGGBBAA
  // The ids clients see. The host follows every command's changes (a body created gets a new
  // id, a removed one loses its id for good); a command that needs a new body's id at once
  // calls ids.sync(world) itself.
  BodyIds ids;
  // Chosen at random when the server starts, and written into snapshots: a snapshot made here
  // gives its bodies back their ids; one from elsewhere gets new ones, which cannot collide with
  // ids this server has handed out.
  std::uint64_t server_instance = 0;
  // Counts wholesale replacements (a scene loaded, a snapshot restored), so that a subscriber
  // forgets every body it knew.
  std::uint64_t epoch = 0;

  // A new world whose bodies all get new ids.
  void replace(World replacement, double new_dt, std::vector<std::uint32_t> new_colours) {
    world = std::move(replacement);
    dt = new_dt;
    colours = std::move(new_colours);
    ids.clear();
    ids.sync(world);
    ++epoch;
  }
  // A restored world whose bodies keep the ids they had (by slot; see BodyIds::adopt).
  void restore(World replacement, double new_dt, std::vector<std::uint32_t> new_colours,
               std::span<const std::uint64_t> wire_ids, std::uint64_t next_id) {
    world = std::move(replacement);
    dt = new_dt;
    colours = std::move(new_colours);
    ids.adopt(world, wire_ids, next_id);
    ++epoch;
  }
  void set_colour(BodyId id, std::uint32_t colour) {
    if (colours.size() <= id.index) colours.resize(id.index + 1, 0);
    colours[id.index] = colour;
  }
};

// One step of the world, shared read-only by every subscriber.
struct FrameData {
  // Encodings of this frame made for one subscriber and kept for the others that asked for the
  // same fields (the gRPC streams fill it; see frame_stream.h).
  struct Encodings {
    std::mutex mutex;
    std::vector<std::pair<std::uint32_t, std::shared_ptr<const std::string>>> by_fields;
  };
  mutable Encodings encodings;

  std::uint64_t epoch = 0;  // HostedWorld::epoch
  std::uint64_t stepped_at_unix_ns = 0;
  std::shared_ptr<const Catalogue> catalogue;
  std::uint64_t step = 0;
  double time = 0;                                            // s, simulated
  std::vector<std::uint64_t> ids;                             // live bodies, slot order
  std::vector<double> positions;                              // x y z per body, m
  std::vector<double> orientations;                           // w x y z per body
  std::vector<double> linear_velocities, angular_velocities;  // x y z per body
  // One entry per contact point.
  std::vector<std::uint64_t> contact_a, contact_b;
  std::vector<double> contact_points, contact_normals, contact_depths, contact_impulses;
  StepStats stats;
};

using FrameMailbox = Mailbox<FrameData>;

struct HostStatus {
  std::uint64_t step = 0;
  double time = 0;
  std::size_t bodies = 0;
  bool running = false;
  double dt = 0, real_time_factor = 0;
  StepStats last_step;
  std::size_t subscribers = 0;
};

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
  std::shared_ptr<const FrameData> make_frame() const;

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
  // The newest frame: a new subscriber starts from it, even while the world is paused.
  std::shared_ptr<const FrameData> last_frame_;
  void publish(std::shared_ptr<const FrameData> frame);
  std::thread thread_;
};

}  // namespace tumble::server
