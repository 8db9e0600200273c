// Recorded streams: a file of frames exactly as the server sent them, so that a run can be
// replayed, drawn or analysed later without the server. The first frame describes every body.
// Format: the line "tumble-recording 1\n", then each Frame as a varint length and its bytes
// (proto/tumble/recording_writer.h).
#pragma once

#include <fstream>
#include <string>

#include "physics/status.h"
#include "tumble/recording_writer.h"
#include "tumble/v1/world.pb.h"

namespace tumble::client {

using tumble::RecordingWriter;  // proto/tumble/recording_writer.h: the server writes them too

class RecordingReader {
 public:
  static Result<RecordingReader> open(const std::string& path);
  // The next frame: true; false at the end of the file, or when what follows is not a whole,
  // sound frame (status() then says what and where: a length past the end of the file, bytes
  // that are not a frame, arrays that do not match the frame's ids).
  bool next(v1::Frame* frame);
  // OK at the end of a whole recording; the reason reading stopped otherwise.
  const Status& status() const { return status_; }
  // How many frames next() has returned.
  std::size_t frames() const { return frames_; }

 private:
  explicit RecordingReader(std::string bytes) : bytes_(std::move(bytes)) {}
  bool stop(const std::string& why);
  std::string bytes_;
  std::size_t offset_ = 0, frames_ = 0;
  Status status_ = Status::ok();
};

}  // namespace tumble::client
