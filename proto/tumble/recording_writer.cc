#include "tumble/recording_writer.h"

#include <google/protobuf/descriptor.pb.h>
#include <zlib.h>

#include <cmath>
#include <functional>
#include <set>
#include <utility>

#include "tumble/v1/recording.pb.h"

namespace tumble {
namespace {

std::uint32_t crc32_of(std::uint32_t crc, std::string_view bytes) {
  return static_cast<std::uint32_t>(
      crc32(crc, reinterpret_cast<const Bytef*>(bytes.data()), static_cast<uInt>(bytes.size())));
}

// The schema of a message as MCAP's protobuf encoding wants it: a FileDescriptorSet of its file
// and every file that file imports, imports first.
std::string descriptor_set(const std::string& message) {
  const google::protobuf::Descriptor* type =
      google::protobuf::DescriptorPool::generated_pool()->FindMessageTypeByName(message);
  google::protobuf::FileDescriptorSet set;
  std::set<std::string> added;
  std::function<void(const google::protobuf::FileDescriptor*)> add =
      [&](const google::protobuf::FileDescriptor* file) {
        if (!added.insert(file->name()).second) return;
        for (int i = 0; i < file->dependency_count(); ++i)
          add(file->dependency(i));
        file->CopyTo(set.add_file());
      };
  add(type->file());
  return set.SerializeAsString();
}

std::string header_record() {
  mcap::Bytes content, out;
  content.put_string("");  // profile: none (our own protobuf messages, not ROS 2's)
  content.put_string("tumble " TUMBLE_RECORDING_LIBRARY_VERSION);
  mcap::put_record(out, mcap::kHeader, content.data());
  return out.data();
}

void put_schema(mcap::Bytes& out, const mcap::ChannelInfo& channel) {
  mcap::Bytes content;
  content.put(channel.id);
  content.put_string(channel.schema);
  content.put_string("protobuf");
  content.put_string(descriptor_set(channel.schema));
  mcap::put_record(out, mcap::kSchema, content.data());
}

void put_channel(mcap::Bytes& out, const mcap::ChannelInfo& channel) {
  mcap::Bytes content;
  content.put(channel.id);
  content.put(channel.id);  // its schema
  content.put_string(channel.topic);
  content.put_string("protobuf");
  content.put(std::uint32_t{0});  // no metadata
  mcap::put_record(out, mcap::kChannel, content.data());
}

// A map<uint16, uint64> as MCAP writes it: a uint32 byte length, then the pairs.
void put_map(mcap::Bytes& out, const std::map<std::uint16_t, std::uint64_t>& map) {
  out.put(static_cast<std::uint32_t>(map.size() * (2 + 8)));
  for (const auto& [key, value] : map) {
    out.put(key);
    out.put(value);
  }
}

}  // namespace

wire::Result<RecordingWriter> RecordingWriter::create(const std::string& path) {
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  if (!file) return wire::Status::error(path + ": cannot create");
  RecordingWriter writer;
  writer.file_ = std::move(file);
  writer.open_ = true;
  mcap::Bytes start;
  start.append(std::string_view(mcap::kMagic, mcap::kMagicSize));
  start.append(header_record());
  for (const mcap::ChannelInfo& channel : mcap::kChannels) {
    put_schema(start, channel);
    put_channel(start, channel);
  }
  if (wire::Status s = writer.put(start.data()); !s)
    return wire::Status::error(path + ": cannot write");
  return writer;
}

RecordingWriter& RecordingWriter::operator=(RecordingWriter&& other) noexcept {
  if (this == &other) return *this;
  if (open_) finish();
  file_ = std::move(other.file_);
  open_ = std::exchange(other.open_, false);
  position_ = other.position_;
  data_crc_ = other.data_crc_;
  chunk_ = std::move(other.chunk_);
  chunk_start_time_ = other.chunk_start_time_;
  chunk_end_time_ = other.chunk_end_time_;
  chunk_opened_ = other.chunk_opened_;
  chunk_messages_ = std::move(other.chunk_messages_);
  chunks_ = std::move(other.chunks_);
  channel_counts_ = std::move(other.channel_counts_);
  messages_ = other.messages_;
  start_time_ = other.start_time_;
  end_time_ = other.end_time_;
  return *this;
}

RecordingWriter::~RecordingWriter() {
  if (open_) finish();
}

wire::Status RecordingWriter::put(std::string_view bytes, bool data_section) {
  file_.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!file_.flush()) {
    open_ = false;
    return wire::Status::error("recording: cannot write (disk full?)");
  }
  if (data_section) data_crc_ = crc32_of(data_crc_, bytes);
  position_ += bytes.size();
  return wire::Status::ok();
}

wire::Status RecordingWriter::add_message(const mcap::ChannelInfo& channel, std::uint32_t sequence,
                                          std::uint64_t log_time, std::uint64_t publish_time,
                                          const google::protobuf::Message& message) {
  if (chunk_.size() == 0) {
    chunk_start_time_ = log_time;
    chunk_end_time_ = log_time;
    chunk_opened_ = std::chrono::steady_clock::now();
  }
  chunk_start_time_ = std::min(chunk_start_time_, log_time);
  chunk_end_time_ = std::max(chunk_end_time_, log_time);
  chunk_messages_[channel.id].push_back({log_time, chunk_.size()});
  mcap::Bytes content;
  content.put(channel.id);
  content.put(sequence);
  content.put(log_time);
  content.put(publish_time);
  content.append(message.SerializeAsString());
  mcap::put_record(chunk_, mcap::kMessage, content.data());
  ++channel_counts_[channel.id];
  ++messages_;
  start_time_ = std::min(start_time_, log_time);
  end_time_ = std::max(end_time_, log_time);
  return wire::Status::ok();
}

wire::Status RecordingWriter::write(const v1::Frame& frame) {
  if (!open_) return wire::Status::error("recording: not open (finished, or a write failed)");
  // Wall-clock time (when the server stepped) orders the messages, as Foxglove's timeline wants;
  // the simulated time is in each message. A frame without it uses the simulated time.
  const std::uint64_t simulated = static_cast<std::uint64_t>(
      std::llround(std::max(0.0, std::min(frame.time(), 1.8e10)) * 1e9));  // within 2^64 ns
  const std::uint64_t log_time =
      frame.stepped_at_unix_ns() != 0 ? frame.stepped_at_unix_ns() : simulated;
  const auto sequence = static_cast<std::uint32_t>(frame.step());
  if (frame.added_size() > 0 || frame.removed_size() > 0) {
    v1::BodyChanges changes;
    changes.set_step(frame.step());
    changes.set_time(frame.time());
    *changes.mutable_added() = frame.added();
    *changes.mutable_removed() = frame.removed();
    add_message(mcap::kBodiesChannel, sequence, log_time, simulated, changes);
  }
  // The frame's own fields, copied one by one: a copy of the whole frame would copy its contacts.
  v1::Frame poses;
  poses.set_step(frame.step());
  poses.set_time(frame.time());
  *poses.mutable_ids() = frame.ids();
  *poses.mutable_positions() = frame.positions();
  *poses.mutable_orientations() = frame.orientations();
  *poses.mutable_linear_velocities() = frame.linear_velocities();
  *poses.mutable_angular_velocities() = frame.angular_velocities();
  poses.set_dropped(frame.dropped());
  poses.set_stepped_at_unix_ns(frame.stepped_at_unix_ns());
  poses.set_changes_only(frame.changes_only());  // bodies not listed are as before
  if (frame.has_joints()) *poses.mutable_joints() = frame.joints();  // a world's joints: few
  *poses.mutable_joints_added() = frame.joints_added();
  *poses.mutable_joints_removed() = frame.joints_removed();
  add_message(mcap::kFramesChannel, sequence, log_time, simulated, poses);
  if (frame.has_contacts())
    add_message(mcap::kContactsChannel, sequence, log_time, simulated, frame.contacts());
  if (frame.has_stats())
    add_message(mcap::kStatsChannel, sequence, log_time, simulated, frame.stats());
  const double age =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - chunk_opened_).count();
  if (chunk_.size() >= kChunkBytes || age >= kChunkSeconds) return flush_chunk();
  return wire::Status::ok();
}

wire::Status RecordingWriter::flush_chunk() {
  if (chunk_.size() == 0) return wire::Status::ok();
  mcap::Bytes content, record;
  content.put(chunk_start_time_);
  content.put(chunk_end_time_);
  content.put(static_cast<std::uint64_t>(chunk_.size()));  // uncompressed size
  content.put(crc32_of(0, chunk_.data()));
  content.put_string("");  // no compression
  content.put(static_cast<std::uint64_t>(chunk_.size()));
  content.append(chunk_.data());
  mcap::put_record(record, mcap::kChunk, content.data());
  ChunkIndex index{chunk_start_time_, chunk_end_time_, position_, record.size(), 0, {}};
  if (wire::Status s = put(record.data()); !s) return s;
  // Each channel's messages in the chunk: (log time, offset within the chunk's records).
  mcap::Bytes indexes;
  for (const auto& [channel, entries] : chunk_messages_) {
    index.index_offsets[channel] = position_ + indexes.size();
    mcap::Bytes entry;
    entry.put(channel);
    entry.put(static_cast<std::uint32_t>(entries.size() * 16));
    for (const auto& [time, offset] : entries) {
      entry.put(time);
      entry.put(offset);
    }
    mcap::put_record(indexes, mcap::kMessageIndex, entry.data());
  }
  index.index_length = indexes.size();
  if (wire::Status s = put(indexes.data()); !s) return s;
  chunks_.push_back(std::move(index));
  chunk_.clear();
  chunk_messages_.clear();
  return wire::Status::ok();
}

wire::Status RecordingWriter::finish() {
  if (!open_) return wire::Status::error("recording: not open (finished, or a write failed)");
  if (wire::Status s = flush_chunk(); !s) return s;
  mcap::Bytes data_end;
  {
    mcap::Bytes content;
    content.put(data_crc_);
    mcap::put_record(data_end, mcap::kDataEnd, content.data());
  }
  if (wire::Status s = put(data_end.data(), false); !s) return s;

  // The summary: schemas, channels, statistics and chunk indexes, each group's place recorded
  // in the summary offsets.
  const std::uint64_t summary_start = position_;
  mcap::Bytes summary;
  struct Group {
    mcap::Opcode opcode;
    std::uint64_t start, length;
  };
  std::vector<Group> groups;
  auto group = [&](mcap::Opcode opcode, const std::function<void()>& records) {
    const std::size_t before = summary.size();
    records();
    groups.push_back({opcode, summary_start + before, summary.size() - before});
  };
  group(mcap::kSchema, [&] {
    for (const mcap::ChannelInfo& channel : mcap::kChannels)
      put_schema(summary, channel);
  });
  group(mcap::kChannel, [&] {
    for (const mcap::ChannelInfo& channel : mcap::kChannels)
      put_channel(summary, channel);
  });
  group(mcap::kStatistics, [&] {
    mcap::Bytes content;
    content.put(messages_);
    content.put(static_cast<std::uint16_t>(std::size(mcap::kChannels)));  // schemas
    content.put(static_cast<std::uint32_t>(std::size(mcap::kChannels)));  // channels
    content.put(std::uint32_t{0});                                        // attachments
    content.put(std::uint32_t{0});                                        // metadata
    content.put(static_cast<std::uint32_t>(chunks_.size()));
    content.put(messages_ > 0 ? start_time_ : std::uint64_t{0});
    content.put(end_time_);
    put_map(content, channel_counts_);
    mcap::put_record(summary, mcap::kStatistics, content.data());
  });
  if (!chunks_.empty())
    group(mcap::kChunkIndex, [&] {
      for (const ChunkIndex& chunk : chunks_) {
        mcap::Bytes content;
        content.put(chunk.start_time);
        content.put(chunk.end_time);
        content.put(chunk.offset);
        content.put(chunk.length);
        put_map(content, chunk.index_offsets);
        content.put(chunk.index_length);
        content.put_string("");
        const std::uint64_t records = chunk.length - 1 - 8 - 8 - 8 - 8 - 4 - 4 - 8;
        content.put(records);  // compressed size: the records, stored as they are
        content.put(records);  // uncompressed size
        mcap::put_record(summary, mcap::kChunkIndex, content.data());
      }
    });
  const std::uint64_t offsets_start = summary_start + summary.size();
  for (const Group& g : groups) {
    mcap::Bytes content;
    content.put(static_cast<std::uint8_t>(g.opcode));
    content.put(g.start);
    content.put(g.length);
    mcap::put_record(summary, mcap::kSummaryOffset, content.data());
  }
  // The footer; its CRC covers the summary and the footer up to the CRC itself.
  mcap::Bytes footer;
  footer.put(static_cast<std::uint8_t>(mcap::kFooter));
  footer.put(std::uint64_t{8 + 8 + 4});
  footer.put(summary_start);
  footer.put(offsets_start);
  footer.put(crc32_of(crc32_of(0, summary.data()), footer.data()));
  summary.append(footer.data());
  summary.append(std::string_view(mcap::kMagic, mcap::kMagicSize));
  wire::Status written = put(summary.data(), false);
  open_ = false;
  file_.close();
  return written;
}

}  // namespace tumble
