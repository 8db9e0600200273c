// Recorded streams: the frames exactly as the server sent them, so that a run can be replayed,
// drawn or analysed later without the server. The first frame describes every body.
//
// Recordings are MCAP files (proto/tumble/recording_writer.h writes them: one channel per kind of
// data, docs/SERVICE.md "Recordings"); this reader puts each step's messages back together into
// the Frame it came from. It also reads the format of Tumble 0.1's first recordings (the line
// "tumble-recording 1\n", then each Frame as a varint length and its bytes).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <string_view>

#include "tumble/wire_status.h"
#include "tumble/recording_writer.h"
#include "tumble/v1/recording.pb.h"
#include "tumble/v1/world.pb.h"

namespace tumble::client {

using tumble::RecordingWriter;  // proto/tumble/recording_writer.h: the server writes them too

inline constexpr char kLegacyRecordingMagic[] = "tumble-recording 1\n";

class RecordingReader {
 public:
  static Result<RecordingReader> open(const std::string& path);
  // The next frame: true; false at the end of the file, or when what follows is not whole and
  // sound (status() then says what and where: a record past the end of the file, a chunk whose
  // CRC does not match, bytes that are not a frame, arrays that do not match the frame's ids).
  // The frames before a cut are all read.
  bool next(v1::Frame* frame);
  // OK at the end of a whole recording; the reason reading stopped otherwise.
  const Status& status() const { return status_; }
  // How many frames next() has returned.
  std::size_t frames() const { return frames_; }

 private:
  enum class Kind { kOther, kBodies, kFrames, kContacts, kStats };
  struct Message {
    Kind kind = Kind::kOther;
    std::string_view data;
  };
  explicit RecordingReader(std::string bytes) : bytes_(std::move(bytes)) {}
  bool stop(const std::string& why);
  bool next_legacy(v1::Frame* frame);
  bool next_mcap(v1::Frame* frame);
  // The next message of the file, from a chunk or from the data section itself.
  bool next_message(Message* message);
  bool read_channel(std::string_view content);
  bool finish_frame(v1::Frame* out);

  std::string bytes_;
  bool mcap_ = false;
  std::size_t offset_ = 0, frames_ = 0;
  Status status_ = Status::ok();
  // MCAP: the chunk being read (its records) and where in it; what each channel carries.
  std::string_view chunk_;
  std::size_t chunk_offset_ = 0;
  std::map<std::uint16_t, Kind> channels_;
  bool ended_ = false;      // DataEnd reached, or the bytes ran out
  bool cut_short_ = false;  // the bytes ran out before DataEnd
  // The frame being put together, and the body changes that came before the next one.
  v1::Frame current_;
  bool has_current_ = false;
  v1::BodyChanges changes_;
  bool has_changes_ = false;
};

}  // namespace tumble::client
