#include "world_host.h"

#include "log.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

namespace tumble::server {

WorldHost::WorldHost(World world, double dt, double real_time_factor)
    : real_time_factor_(real_time_factor) {
  hosted_.world = std::move(world);
  hosted_.dt = dt;
  hosted_.ids.sync(hosted_.world);
  hosted_.joint_ids.sync(hosted_.world);  // the scene's joints
  std::random_device entropy;
  while (hosted_.server_instance == 0)
    hosted_.server_instance = static_cast<std::uint64_t>(entropy()) << 32 | entropy();
  refresh_catalogue();
  status_.bodies = hosted_.world.body_count();
  status_.joints = hosted_.world.joint_count();
  status_.dt = dt;
  status_.real_time_factor = real_time_factor_;
  status_.settings = hosted_.world.settings();
  last_frame_ = make_frame(dt);  // the state before the first step
  thread_ = std::thread([this] { run(); });
}

WorldHost::~WorldHost() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
  for (Command& command : commands_)
    command.done.set_value(Status::error("server: shutting down", StatusCode::kUnavailable));
  for (const auto& mailbox : subscribers_)
    mailbox->close();
}

Status WorldHost::submit(Command command) {
  std::future<Status> done;
  {
    std::lock_guard lock(mutex_);
    if (stopping_) return Status::error("server: shutting down", StatusCode::kUnavailable);
    commands_.push_back(std::move(command));
    done = commands_.back().done.get_future();
  }
  wake_.notify_all();
  return done.get();
}

Status WorldHost::apply(std::function<Status(HostedWorld&)> change) {
  return submit({std::move(change), {}, false});
}

void WorldHost::inspect(std::function<void(const HostedWorld&)> read) {
  submit({[&read](HostedWorld& hosted) {
            read(hosted);
            return Status::ok();
          },
          {},
          true});
}

void WorldHost::play() {
  {
    std::lock_guard lock(mutex_);
    running_ = true;
  }
  wake_.notify_all();
}

void WorldHost::pause() {
  std::lock_guard lock(mutex_);
  running_ = false;
  steps_left_ = 0;
  status_.behind = false;  // nothing is due while paused
}

void WorldHost::step(std::uint64_t steps) {
  {
    std::lock_guard lock(mutex_);
    running_ = false;
    steps_left_ += steps;
  }
  wake_.notify_all();
}

Status WorldHost::set_dt(double dt) {
  if (!std::isfinite(dt) || !(dt >= kMinTimeStep))
    return Status::error("dt: must be finite and at least the shortest step");
  std::lock_guard lock(mutex_);
  hosted_.dt = dt;
  return Status::ok();
}

Status check_real_time_factor(double factor) {
  // A tiny factor would put the next step beyond what the clock's integer nanoseconds can hold.
  if (factor == 0 || (factor >= kMinRealTimeFactor && factor <= kMaxRealTimeFactor))
    return Status::ok();
  return Status::error("real_time_factor: must be 0 (as fast as possible) or within [" +
                       std::to_string(kMinRealTimeFactor) + ", " +
                       std::to_string(kMaxRealTimeFactor) + "]");
}

Status WorldHost::set_real_time_factor(double factor) {
  if (Status s = check_real_time_factor(factor); !s) return s;
  {
    std::lock_guard lock(mutex_);
    real_time_factor_ = factor;
  }
  wake_.notify_all();
  return Status::ok();
}

bool WorldHost::wait_idle(std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  return idle_.wait_for(lock, timeout, [&] { return !running_ && steps_left_ == 0 && !in_step_; });
}

std::shared_ptr<FrameMailbox> WorldHost::subscribe() {
  auto mailbox = std::make_shared<FrameMailbox>();
  std::lock_guard lock(mutex_);
  if (last_frame_ != nullptr) mailbox->put(last_frame_);
  subscribers_.push_back(mailbox);
  return mailbox;
}

void WorldHost::unsubscribe(const std::shared_ptr<FrameMailbox>& mailbox) {
  mailbox->close();
  std::lock_guard lock(mutex_);
  std::erase(subscribers_, mailbox);
}

HostStatus WorldHost::status() const {
  std::lock_guard lock(mutex_);
  HostStatus status = status_;
  status.running = running_ || steps_left_ > 0 || in_step_;
  status.dt = hosted_.dt;
  status.real_time_factor = real_time_factor_;
  status.subscribers = subscribers_.size();
  return status;
}

// With the lock held.
void WorldHost::record_to(std::shared_ptr<FrameSink> sink) {
  std::lock_guard lock(mutex_);
  sink_ = std::move(sink);
  if (sink_ != nullptr && last_frame_ != nullptr) sink_->put(last_frame_);
}

void WorldHost::publish(std::shared_ptr<const FrameData> frame) {
  if (sink_ != nullptr) sink_->put(frame);
  last_frame_ = frame;
  for (const auto& mailbox : subscribers_)
    mailbox->put(frame);
}

// Runs on the stepping thread with the lock held. When a command changed the world, subscribers
// see the change at once in a frame of the same step (a paused world too).
void WorldHost::apply_pending() {
  bool changed = false;
  while (!commands_.empty()) {
    Command command = std::move(commands_.front());
    commands_.pop_front();
    const Status result = command.change(hosted_);
    if (result && !command.read_only) {
      changed = true;
      hosted_.ids.sync(hosted_.world);
      hosted_.joint_ids.sync(hosted_.world);
      refresh_catalogue();
    }
    status_.bodies = hosted_.world.body_count();
    status_.joints = hosted_.world.joint_count();
    status_.step = hosted_.world.step_count();  // a command may have replaced the world
    status_.time = hosted_.world.time();
    status_.settings = hosted_.world.settings();
    command.done.set_value(result);
  }
  if (changed) publish(make_frame(hosted_.dt));
}

void WorldHost::refresh_catalogue() {
  catalogue_ = updated_catalogue(hosted_, catalogue_, catalogue_epoch_);
  catalogue_epoch_ = hosted_.epoch;
}

std::shared_ptr<const FrameData> WorldHost::make_frame(double dt) {
  note_changes(hosted_);
  return server::make_frame(hosted_, dt, catalogue_);
}

void WorldHost::run() {
  using Clock = std::chrono::steady_clock;
  std::unique_lock lock(mutex_);
  // Pacing: simulated time since `epoch` over the real-time factor is when the next step is due.
  Clock::time_point epoch = Clock::now();
  double paced_time = 0;
  bool was_stepping = false;
  // The window over which the achieved real-time factor is measured.
  Clock::time_point window_start = epoch;
  double window_time = 0;
  while (true) {
    apply_pending();
    if (stopping_) return;
    const bool stepping = running_ || steps_left_ > 0;
    if (!stepping) {
      was_stepping = false;
      status_.behind = false;
      idle_.notify_all();
      wake_.wait(lock, [&] { return stopping_ || !commands_.empty() || running_ || steps_left_; });
      continue;
    }
    if (!was_stepping) {  // (re)start the pacing clock
      epoch = Clock::now();
      paced_time = 0;
      was_stepping = true;
      window_start = epoch;
      window_time = status_.time;
    }
    if (running_ && real_time_factor_ > 0) {
      const auto due = epoch + std::chrono::duration_cast<Clock::duration>(
                                   std::chrono::duration<double>(paced_time / real_time_factor_));
      const Clock::time_point now = Clock::now();
      if (now < due) {
        if (status_.behind) {
          status_.behind = false;
          log(LogLevel::kInfo, "the world keeps its real-time factor again");
        }
        // Commands and control still get through while waiting.
        wake_.wait_until(lock, due, [&] { return stopping_ || !commands_.empty() || !running_; });
        continue;
      }
      if (std::chrono::duration<double>(now - due).count() > kBehindSeconds) {
        if (!status_.behind) {
          status_.behind = true;
          ++status_.times_behind;
          char message[256];
          std::snprintf(message, sizeof message,
                        "the world fell behind its real-time factor %g: the last step took "
                        "%.3g ms, one is due every %.3g ms (fewer bodies, a larger dt or a lower "
                        "factor would help)",
                        real_time_factor_, 1e3 * status_.last_step.time.total,
                        1e3 * hosted_.dt / real_time_factor_);
          log(LogLevel::kWarn, message);
        }
        epoch = now;  // the debt is forgiven: running flat out to pay it would only lag more
        paced_time = 0;
      }
    }
    const double dt = hosted_.dt;
    if (steps_left_ > 0) --steps_left_;
    in_step_ = true;
    const std::shared_ptr<FrameSink> sink = sink_;
    lock.unlock();  // the world is this thread's alone; callers may queue meanwhile
    if (sink != nullptr) sink->wait_for_room();  // a lossless recording sets the pace
    const Status stepped = hosted_.world.step(dt);
    std::shared_ptr<const FrameData> frame = stepped ? make_frame(dt) : nullptr;
    lock.lock();
    in_step_ = false;
    paced_time += dt;
    status_.step = hosted_.world.step_count();
    status_.time = hosted_.world.time();
    status_.last_step = hosted_.world.last_step();
    const Clock::time_point now = Clock::now();
    if (const double wall = std::chrono::duration<double>(now - window_start).count(); wall >= 1) {
      // (A world replaced meanwhile may have gone back in time: that window says nothing.)
      if (status_.time >= window_time)
        status_.achieved_real_time_factor = (status_.time - window_time) / wall;
      window_start = now;
      window_time = status_.time;
    }
    if (frame != nullptr) publish(std::move(frame));
  }
}

}  // namespace tumble::server
