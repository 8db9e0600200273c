// What one reader of frames (a subscriber, the server's own recording) has been told about the
// bodies: each frame it gets describes the bodies new to it and lists the ones gone, so that a
// viewer or a file reader can draw what it was not told about before.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "frame.h"
#include "tumble/v1/world.pb.h"

namespace tumble::server {

class CatalogueDiff {
 public:
  // Adds to `out` the descriptions of the bodies of `frame` (of those in `only`, sorted; empty:
  // all) this reader has not had, and the ids it had that are gone.
  void add_changes(const FrameData& frame, const std::vector<std::uint64_t>& only, v1::Frame* out);
  // The same for the joints (every joint, whichever bodies were asked for).
  void add_joint_changes(const FrameData& frame, v1::Frame* out);

 private:
  std::uint64_t epoch_ = 0;
  std::vector<std::uint64_t> known_;  // ids this reader has descriptions of, sorted
  std::shared_ptr<const Catalogue> known_catalogue_;
  std::uint64_t joints_epoch_ = 0;
  std::shared_ptr<const JointCatalogue> known_joints_;  // the last joint catalogue diffed
};

}  // namespace tumble::server
