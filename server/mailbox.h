// A subscriber's mailbox: holds the newest frame only. Publishing never waits for a reader; a
// frame replaced before it was read is counted as dropped, so a slow, stalled or vanished
// subscriber costs the world one pointer swap per step and never more memory than one frame.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>

namespace tumble::server {

// Told when a frame arrives, so that a reader need not wait on the mailbox (the callback streams).
class MailboxListener {
 public:
  virtual ~MailboxListener() = default;
  virtual void frame_arrived() = 0;
};

template <class Frame>
class Mailbox {
 public:
  struct Delivery {
    std::shared_ptr<const Frame> frame;
    std::uint64_t dropped = 0;  // frames replaced unread since the previous delivery
  };

  // Never blocks on a reader (the lock guards a pointer swap only). The listener, if any, is told
  // outside the lock.
  void put(std::shared_ptr<const Frame> frame) {
    std::shared_ptr<MailboxListener> listener;
    {
      std::lock_guard lock(mutex_);
      if (closed_) return;
      if (frame_ != nullptr) ++dropped_;
      frame_ = std::move(frame);
      listener = listener_;
    }
    ready_.notify_one();
    if (listener != nullptr) listener->frame_arrived();
  }

  void set_listener(std::shared_ptr<MailboxListener> listener) {
    std::lock_guard lock(mutex_);
    listener_ = std::move(listener);
  }

  // The newest frame, waiting up to `timeout` for one; nothing when the time runs out or the
  // mailbox is closed and empty.
  std::optional<Delivery> take(std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    ready_.wait_for(lock, timeout, [&] { return frame_ != nullptr || closed_; });
    if (frame_ == nullptr) return std::nullopt;
    Delivery delivery{std::move(frame_), dropped_};
    frame_ = nullptr;
    dropped_ = 0;
    return delivery;
  }

  // Wakes a waiting reader; later frames are discarded.
  void close() {
    {
      std::lock_guard lock(mutex_);
      closed_ = true;
    }
    ready_.notify_all();
  }

  bool closed() const {
    std::lock_guard lock(mutex_);
    return closed_;
  }

 private:
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::shared_ptr<const Frame> frame_;
  std::shared_ptr<MailboxListener> listener_;
  std::uint64_t dropped_ = 0;
  bool closed_ = false;
};

}  // namespace tumble::server
