// A reader of every frame the host publishes, none dropped (the server's own recording): unlike a
// subscriber's mailbox, which keeps the newest frame only, a sink takes each one, and the host
// waits before a step until the sink has room for its frame.
#pragma once

#include <memory>

#include "frame.h"

namespace tumble::server {

class FrameSink {
 public:
  virtual ~FrameSink() = default;
  // Takes a frame; never blocks (the host may hold its lock).
  virtual void put(std::shared_ptr<const FrameData> frame) = 0;
  // Returns once a step's frame would find room (called by the stepping thread without its
  // lock, before each step).
  virtual void wait_for_room() = 0;
};

}  // namespace tumble::server
