#include "frame_source.h"

#include <thread>

namespace tumble::viewer {

void ServerSource::open() {
  v1::StreamFramesRequest request;
  request.set_contacts(contacts_);
  request.set_joints(joints_);
  // The view keeps every body's pose from frame to frame (WorldView::apply), so it asks for the
  // bodies that changed only: a sleeping world then costs the viewer nothing a frame.
  request.set_changes_only(true);
  client::FrameStream stream = client_.subscribe(request);
  std::lock_guard lock(mutex_);
  stream_.emplace(std::move(stream));
  if (cancelled_) stream_->cancel();
}

bool ServerSource::next(v1::Frame* frame) {
  return stream_ && stream_->next(frame);
}

void ServerSource::cancel() {
  std::lock_guard lock(mutex_);
  cancelled_ = true;
  if (stream_) stream_->cancel();
}

Status ServerSource::finish() {
  return stream_ ? stream_->finish() : Status::ok();
}

Result<std::unique_ptr<RecordingSource>> RecordingSource::open_file(const std::string& path,
                                                                    bool paced) {
  std::unique_ptr<RecordingSource> source(new RecordingSource(path, paced));
  Result<client::RecordingReader> reader = client::RecordingReader::open(path);
  if (!reader) return reader.status();
  source->reader_.emplace(std::move(reader).value());
  return source;
}

void RecordingSource::open() {
  first_time_ = -1;
}  // the file is opened once, by open_file

bool RecordingSource::next(v1::Frame* frame) {
  if (!reader_ || !reader_->next(frame)) {
    if (reader_) status_ = reader_->status();
    return false;
  }
  if (!paced_) return true;
  if (first_time_ < 0) {
    first_time_ = frame->time();
    start_ = std::chrono::steady_clock::now();
  }
  // Sleeps in short pieces, so that cancel() is seen within 50 ms.
  const auto due = start_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                std::chrono::duration<double>(frame->time() - first_time_));
  while (std::chrono::steady_clock::now() < due) {
    {
      std::lock_guard lock(mutex_);
      if (cancelled_) return false;
    }
    std::this_thread::sleep_for(std::min<std::chrono::steady_clock::duration>(
        due - std::chrono::steady_clock::now(), std::chrono::milliseconds(50)));
  }
  return true;
}

void RecordingSource::cancel() {
  std::lock_guard lock(mutex_);
  cancelled_ = true;
}

Status RecordingSource::finish() {
  return status_;
}

}  // namespace tumble::viewer
