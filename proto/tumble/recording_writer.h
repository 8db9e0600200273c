// Recordings of frames, written as MCAP (proto/tumble/mcap.h; docs/SERVICE.md, "Recordings"), the
// format Foxglove and the ROS 2 tools open: one channel per kind of data (body changes, frames,
// contacts, statistics), each message a protobuf of ours whose schema the file embeds, in
// uncompressed chunks with their indexes, CRCs and a summary. The client's `tumble record` and the
// server's own `--record` write them; client/recording.h reads them.
#pragma once

#include <chrono>
#include <cstdint>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "tumble/mcap.h"
#include "tumble/v1/world.pb.h"
#include "tumble/wire_status.h"

namespace tumble {

class RecordingWriter {
 public:
  static wire::Result<RecordingWriter> create(const std::string& path);
  RecordingWriter(RecordingWriter&& other) noexcept { *this = std::move(other); }
  RecordingWriter& operator=(RecordingWriter&& other) noexcept;
  ~RecordingWriter();  // finishes the file if finish() was not called

  // A chunk goes to the file once it holds kChunkBytes or is kChunkSeconds old, so a recording
  // cut short (the process killed) loses at most that much; its readers still read it.
  wire::Status write(const v1::Frame& frame);
  // The last chunk, the indexes and the summary: the file is whole.
  wire::Status finish();

  static constexpr std::size_t kChunkBytes = 256 << 10;
  static constexpr double kChunkSeconds = 0.5;

 private:
  RecordingWriter() = default;
  wire::Status put(std::string_view bytes, bool data_section = true);
  wire::Status add_message(const mcap::ChannelInfo& channel, std::uint32_t sequence,
                           std::uint64_t log_time, std::uint64_t publish_time,
                           const google::protobuf::Message& message);
  wire::Status flush_chunk();

  struct ChunkIndex {
    std::uint64_t start_time, end_time, offset, length, index_length;
    std::map<std::uint16_t, std::uint64_t> index_offsets;
  };

  std::ofstream file_;
  bool open_ = false;
  std::uint64_t position_ = 0;  // bytes written
  std::uint32_t data_crc_ = 0;  // of everything before DataEnd
  mcap::Bytes chunk_;           // the records of the chunk being gathered
  std::uint64_t chunk_start_time_ = 0, chunk_end_time_ = 0;
  std::chrono::steady_clock::time_point chunk_opened_;
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_messages_;
  std::vector<ChunkIndex> chunks_;
  std::map<std::uint16_t, std::uint64_t> channel_counts_;
  std::uint64_t messages_ = 0, start_time_ = UINT64_MAX, end_time_ = 0;
};

}  // namespace tumble
