// Recorded streams: a file of frames exactly as the server sent them, so that a run can be
// replayed, drawn or analysed later without the server. The first frame describes every body.
// Format: the line "tumble-recording 1\n", then each Frame as a varint length and its bytes.
#pragma once

#include <fstream>
#include <string>

#include "physics/status.h"
#include "tumble/v1/world.pb.h"

namespace tumble::client {

class RecordingWriter {
 public:
  static Result<RecordingWriter> create(const std::string& path);
  // Written through to the file, so a recording cut short loses at most the frame in flight.
  Status write(const v1::Frame& frame);

 private:
  explicit RecordingWriter(std::ofstream file) : file_(std::move(file)) {}
  std::ofstream file_;
};

class RecordingReader {
 public:
  static Result<RecordingReader> open(const std::string& path);
  // The next frame: true, or false at the end. A frame cut off at the end of the file (the
  // recorder was killed mid-write) is reported by truncated().
  bool next(v1::Frame* frame);
  bool truncated() const { return truncated_; }

 private:
  explicit RecordingReader(std::string bytes) : bytes_(std::move(bytes)) {}
  std::string bytes_;
  std::size_t offset_ = 0;
  bool truncated_ = false;
};

}  // namespace tumble::client
