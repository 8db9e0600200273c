// The server's own recording (tumble-server --record FILE): every frame the world makes, none
// dropped, with velocities, contacts and statistics, in the recording format `tumble replay` and
// `tumble-viewer --replay` read (proto/tumble/recording_writer.h). A subscriber recording over
// the network loses frames when it falls behind; this one cannot: a writer thread takes frames
// from a queue of at most kQueuedFrames, and when the disk falls behind the world waits for it.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "catalogue_diff.h"
#include "convert.h"
#include "frame_sink.h"
#include "tumble/recording_writer.h"

namespace tumble::server {

class FrameRecorder final : public FrameSink {
 public:
  static constexpr std::size_t kQueuedFrames = 64;

  // Creates the file (refused: the reason), and starts the writer.
  static Result<std::shared_ptr<FrameRecorder>> start(const std::string& path);
  // Writes what is queued and stops the writer; then status(). The destructor does it too.
  Status finish();
  ~FrameRecorder() override;

  void put(std::shared_ptr<const FrameData> frame) override;
  void wait_for_room() override;

  std::uint64_t frames_written() const;
  // OK, or why writing stopped (the frames after it are not in the file).
  Status status() const;

 private:
  explicit FrameRecorder(RecordingWriter writer);
  void write_frames();

  RecordingWriter writer_;
  bool closed_ = false;  // finish() has finished the file
  FrameOptions options_;
  CatalogueDiff catalogue_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::shared_ptr<const FrameData>> queue_;
  bool stopping_ = false;
  std::uint64_t written_ = 0;
  Status status_ = Status::ok();
  std::thread thread_;
};

}  // namespace tumble::server
