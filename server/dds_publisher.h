// Publishes the world's states on DDS (Cyclone DDS, C API) for tools that speak DDS rather than
// gRPC: ROS 2 tools, or any DDS program built from proto/dds/tumble_states.idl (topics and QoS
// are listed there). It is one more subscriber of the host: a thread of its own takes the newest
// frame from its mailbox and writes it, so publishing never blocks the step loop; a frame that
// arrives while the previous one is still being written replaces it (the newest wins, as DDS's
// keep-last-1 does on the wire).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <thread>
#include <unordered_map>
#include <vector>

#include "world_host.h"

namespace tumble::server {

struct DdsOptions {
  std::uint32_t domain = 0;
  double rate = 0;  // Hz: frames per second at most; 0 publishes every step
};

class DdsPublisher {
 public:
  // Joins the domain and starts publishing the host's frames; says why when it cannot.
  static Result<std::unique_ptr<DdsPublisher>> start(WorldHost& host, DdsOptions options);
  ~DdsPublisher();  // stops the thread and leaves the domain
  DdsPublisher(const DdsPublisher&) = delete;
  DdsPublisher& operator=(const DdsPublisher&) = delete;

  // Steps published so far, and frames skipped because a newer one came first or the rate cap.
  std::uint64_t published() const { return published_; }
  std::uint64_t skipped() const { return skipped_; }

 private:
  struct Writers;
  DdsPublisher(WorldHost& host, DdsOptions options, std::unique_ptr<Writers> writers);
  void run();
  void publish(const FrameData& frame);
  // Writes the bodies that are new since the last catalogue and disposes the ones gone.
  void publish_catalogue(const FrameData& frame);

  WorldHost& host_;
  DdsOptions options_;
  std::unique_ptr<Writers> writers_;
  std::shared_ptr<FrameMailbox> mailbox_;
  std::shared_ptr<const Catalogue> catalogue_;  // the last one published
  // Ids with a live instance on rt/tumble/bodies, and the instance each occupies; instances of
  // removed bodies are used again (lowest first), so the instances are at most the most bodies
  // ever alive at once.
  std::unordered_map<std::uint64_t, std::uint32_t> described_;
  std::vector<std::uint32_t> free_instances_;  // a min-heap
  std::uint32_t next_instance_ = 0;
  std::atomic<std::uint64_t> published_{0}, skipped_{0};
  std::atomic<bool> stopping_{false};
  std::thread thread_;
};

}  // namespace tumble::server
