#include "frame_recorder.h"

#include "log.h"

namespace tumble::server {
namespace {

// The recording writer's failure (the clients' error type) as the server's.
Status from_wire(const wire::Status& status) {
  return status ? Status::ok() : Status::error(status.message());
}

}  // namespace

Result<std::shared_ptr<FrameRecorder>> FrameRecorder::start(const std::string& path) {
  wire::Result<RecordingWriter> writer = RecordingWriter::create(path);
  if (!writer) return from_wire(writer.status());
  std::shared_ptr<FrameRecorder> recorder(new FrameRecorder(std::move(writer).value()));
  recorder->thread_ = std::thread([raw = recorder.get()] { raw->write_frames(); });
  return recorder;
}

FrameRecorder::FrameRecorder(RecordingWriter writer) : writer_(std::move(writer)) {
  options_.velocities = options_.contacts = options_.stats = options_.joints = true;
}

Status FrameRecorder::finish() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
  std::lock_guard lock(mutex_);
  if (!closed_) {
    closed_ = true;
    // The last chunk, the indexes and the summary (unless a write already failed).
    if (status_) status_ = from_wire(writer_.finish());
  }
  return status_;
}

FrameRecorder::~FrameRecorder() {
  finish();
}

void FrameRecorder::put(std::shared_ptr<const FrameData> frame) {
  {
    std::lock_guard lock(mutex_);
    // Past a write error nothing more is kept: the world goes on, the log said why.
    if (!status_) return;
    queue_.push_back(std::move(frame));
  }
  changed_.notify_all();
}

void FrameRecorder::wait_for_room() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return queue_.size() < kQueuedFrames || !status_ || stopping_; });
}

void FrameRecorder::write_frames() {
  std::unique_lock lock(mutex_);
  while (true) {
    changed_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
    if (queue_.empty()) return;  // stopping, and everything written
    const std::shared_ptr<const FrameData> data = std::move(queue_.front());
    queue_.pop_front();
    lock.unlock();
    changed_.notify_all();  // room for the stepping thread
    v1::Frame frame;
    frame_to_proto(*data, options_, &frame);
    catalogue_.add_changes(*data, {}, &frame);
    catalogue_.add_joint_changes(*data, &frame);
    const Status written = from_wire(writer_.write(frame));
    lock.lock();
    if (!written) {
      status_ = written;
      queue_.clear();
      log(LogLevel::kError, "--record: " + written.message() + "; the recording stops at frame " +
                                std::to_string(written_));
      changed_.notify_all();
      return;
    }
    ++written_;
  }
}

std::uint64_t FrameRecorder::frames_written() const {
  std::lock_guard lock(mutex_);
  return written_;
}

Status FrameRecorder::status() const {
  std::lock_guard lock(mutex_);
  return status_;
}

}  // namespace tumble::server
