// Recordings of frames, written: the line "tumble-recording 1\n", then each tumble.v1.Frame as a
// varint length and its bytes. The client's `tumble record` and the server's own `--record`
// write them; client/recording.h reads them.
#pragma once

#include <fstream>
#include <string>

#include "physics/status.h"
#include "tumble/v1/world.pb.h"

namespace tumble {

inline constexpr char kRecordingMagic[] = "tumble-recording 1\n";

class RecordingWriter {
 public:
  static Result<RecordingWriter> create(const std::string& path);
  // Written through to the file, so a recording cut short loses at most the frame in flight.
  Status write(const v1::Frame& frame);

 private:
  explicit RecordingWriter(std::ofstream file) : file_(std::move(file)) {}
  std::ofstream file_;
};

}  // namespace tumble
