#include "recording.h"

#include "frame_format.h"

#include <google/protobuf/io/coded_stream.h>
#include <zlib.h>

#include <fstream>
#include <sstream>

#include "tumble/mcap.h"

namespace tumble::client {
namespace {
constexpr std::size_t kLegacyMagicLength = sizeof kLegacyRecordingMagic - 1;
}  // namespace

Result<RecordingReader> RecordingReader::open(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return Status::error(path + ": cannot open");
  std::stringstream bytes;
  bytes << file.rdbuf();
  std::string data = std::move(bytes).str();
  const bool mcap = data.compare(0, mcap::kMagicSize, mcap::kMagic, mcap::kMagicSize) == 0;
  const bool legacy = data.compare(0, kLegacyMagicLength, kLegacyRecordingMagic) == 0;
  if (!mcap && !legacy)
    return Status::error(path +
                         ": not a tumble recording (neither an MCAP file nor one of "
                         "'tumble-recording 1')");
  RecordingReader reader(std::move(data));
  reader.mcap_ = mcap;
  reader.offset_ = mcap ? mcap::kMagicSize : kLegacyMagicLength;
  if (mcap) {
    mcap::Cursor cursor(std::string_view(reader.bytes_).substr(reader.offset_));
    std::uint8_t opcode = 0;
    if (!cursor.get(&opcode) || opcode != mcap::kHeader)
      return Status::error(path + ": an MCAP file without its header record");
  }
  return reader;
}

bool RecordingReader::stop(const std::string& why) {
  status_ = Status::error("byte " + std::to_string(offset_) + " (frame " +
                          std::to_string(frames_ + 1) + "): " + why);
  offset_ = bytes_.size();
  ended_ = true;
  has_current_ = false;
  return false;
}

bool RecordingReader::next(v1::Frame* frame) {
  return mcap_ ? next_mcap(frame) : next_legacy(frame);
}

bool RecordingReader::next_legacy(v1::Frame* frame) {
  if (offset_ >= bytes_.size()) return false;
  const std::size_t left = bytes_.size() - offset_;
  google::protobuf::io::CodedInputStream input(
      reinterpret_cast<const std::uint8_t*>(bytes_.data() + offset_),
      static_cast<int>(std::min<std::size_t>(left, INT32_MAX)));
  // Read whole, as 64 bits: a length of 2^32 + n must not pass for n.
  std::uint64_t length = 0;
  if (!input.ReadVarint64(&length)) return stop("the file ends inside a frame's length");
  const std::size_t start = offset_ + static_cast<std::size_t>(input.CurrentPosition());
  if (length > bytes_.size() - start)
    return stop("a frame of " + std::to_string(length) + " bytes, but " +
                std::to_string(bytes_.size() - start) +
                " are left (the recording was cut short, or this is not one)");
  if (length > static_cast<std::uint64_t>(INT32_MAX) ||
      !frame->ParseFromArray(bytes_.data() + start, static_cast<int>(length)))
    return stop("not a frame (its bytes do not parse)");
  if (Status s = check_frame(*frame); !s) return stop(s.message());
  offset_ = start + static_cast<std::size_t>(length);
  ++frames_;
  return true;
}

bool RecordingReader::read_channel(std::string_view content) {
  mcap::Cursor cursor(content);
  std::uint16_t id = 0, schema = 0;
  std::string_view topic, encoding;
  if (!cursor.get(&id) || !cursor.get(&schema) || !cursor.get_string(&topic) ||
      !cursor.get_string(&encoding))
    return stop("a channel record cut short");
  Kind kind = Kind::kOther;
  for (const auto& [ours, named] : {std::pair{Kind::kBodies, mcap::kBodiesChannel},
                                    std::pair{Kind::kFrames, mcap::kFramesChannel},
                                    std::pair{Kind::kContacts, mcap::kContactsChannel},
                                    std::pair{Kind::kStats, mcap::kStatsChannel}})
    if (topic == named.topic) kind = ours;
  if (kind != Kind::kOther && encoding != "protobuf")
    return stop("channel " + std::string(topic) + " in " + std::string(encoding) +
                ", not protobuf");
  channels_[id] = kind;
  return true;
}

bool RecordingReader::next_message(Message* message) {
  while (!ended_) {
    // A record: from the chunk being read, else from the data section.
    const bool in_chunk = chunk_offset_ < chunk_.size();
    std::string_view source =
        in_chunk ? chunk_.substr(chunk_offset_) : std::string_view(bytes_).substr(offset_);
    if (!in_chunk && source.empty()) {
      ended_ = cut_short_ = true;  // no DataEnd: what the recording holds is read all the same
      return false;
    }
    mcap::Cursor cursor(source);
    std::uint8_t opcode = 0;
    std::uint64_t length = 0;
    std::string_view content;
    if (!cursor.get(&opcode) || !cursor.get(&length) || length > cursor.rest().size() ||
        !cursor.take(static_cast<std::size_t>(length), &content)) {
      if (in_chunk) return stop("a record runs past the end of its chunk");
      ended_ = cut_short_ = true;  // cut short inside a record: the frames before it stand
      return false;
    }
    (in_chunk ? chunk_offset_ : offset_) += cursor.offset();
    switch (opcode) {
      case mcap::kChannel:
        if (!read_channel(content)) return false;
        break;
      case mcap::kMessage: {
        mcap::Cursor fields(content);
        std::uint16_t channel = 0;
        std::uint32_t sequence = 0;
        std::uint64_t log_time = 0, publish_time = 0;
        if (!fields.get(&channel) || !fields.get(&sequence) || !fields.get(&log_time) ||
            !fields.get(&publish_time))
          return stop("a message record cut short");
        const auto known = channels_.find(channel);
        if (known == channels_.end())
          return stop("a message on channel " + std::to_string(channel) +
                      ", which no channel record defined before it");
        if (known->second == Kind::kOther) break;
        *message = {known->second, fields.rest()};
        return true;
      }
      case mcap::kChunk: {
        if (in_chunk) return stop("a chunk inside a chunk");
        mcap::Cursor fields(content);
        std::uint64_t start = 0, end = 0, size = 0, records_length = 0;
        std::uint32_t crc = 0;
        std::string_view compression, records;
        if (!fields.get(&start) || !fields.get(&end) || !fields.get(&size) || !fields.get(&crc) ||
            !fields.get_string(&compression) || !fields.get(&records_length) ||
            records_length > fields.rest().size() ||
            !fields.take(static_cast<std::size_t>(records_length), &records))
          return stop("a chunk record cut short");
        if (!compression.empty())
          return stop("a chunk compressed with " + std::string(compression) +
                      " (recordings of Tumble are not compressed; `mcap convert` undoes it)");
        if (size != records.size()) return stop("a chunk whose size does not match its records");
        if (crc != 0 && crc != static_cast<std::uint32_t>(
                                   crc32(0, reinterpret_cast<const Bytef*>(records.data()),
                                         static_cast<uInt>(records.size()))))
          return stop("a chunk whose CRC does not match its records (the file is damaged)");
        chunk_ = records;
        chunk_offset_ = 0;
        break;
      }
      case mcap::kDataEnd: {
        if (in_chunk) return stop("a data end inside a chunk");
        ended_ = true;
        // The summary and the footer follow, and the file ends as it began.
        const std::string_view tail = std::string_view(bytes_).substr(offset_);
        constexpr std::size_t kFooterRecord = 1 + 8 + 8 + 8 + 4;
        if (tail.size() < kFooterRecord + mcap::kMagicSize ||
            tail.substr(tail.size() - mcap::kMagicSize) !=
                std::string_view(mcap::kMagic, mcap::kMagicSize) ||
            static_cast<std::uint8_t>(tail[tail.size() - mcap::kMagicSize - kFooterRecord]) !=
                mcap::kFooter)
          cut_short_ = true;
        return false;
      }
      default:  // header, schemas, indexes, attachments, metadata: not needed to read frames
        break;
    }
  }
  return false;
}

bool RecordingReader::finish_frame(v1::Frame* out) {
  *out = std::move(current_);
  has_current_ = false;
  if (Status s = check_frame(*out); !s) return stop(s.message());
  ++frames_;
  return true;
}

bool RecordingReader::next_mcap(v1::Frame* frame) {
  Message message;
  while (next_message(&message)) {
    const void* data = message.data.data();
    const int size = static_cast<int>(std::min<std::size_t>(message.data.size(), INT32_MAX));
    switch (message.kind) {
      case Kind::kBodies:
        if (!changes_.ParseFromArray(data, size)) return stop("body changes that do not parse");
        has_changes_ = true;
        break;
      case Kind::kFrames: {
        v1::Frame next;
        if (!next.ParseFromArray(data, size)) return stop("not a frame (its bytes do not parse)");
        if (has_changes_) {
          if (changes_.step() != next.step())
            return stop("body changes of step " + std::to_string(changes_.step()) +
                        " before the frame of step " + std::to_string(next.step()));
          *next.mutable_added() = std::move(*changes_.mutable_added());
          *next.mutable_removed() = std::move(*changes_.mutable_removed());
          has_changes_ = false;
        }
        if (!has_current_) {
          current_ = std::move(next);
          has_current_ = true;
          break;
        }
        v1::Frame done = std::move(current_);
        current_ = std::move(next);
        if (Status s = check_frame(done); !s) return stop(s.message());
        *frame = std::move(done);
        ++frames_;
        return true;
      }
      case Kind::kContacts:
        if (!has_current_) return stop("contacts before any frame");
        if (!current_.mutable_contacts()->ParseFromArray(data, size))
          return stop("contacts that do not parse");
        break;
      case Kind::kStats:
        if (!has_current_) return stop("statistics before any frame");
        if (!current_.mutable_stats()->ParseFromArray(data, size))
          return stop("statistics that do not parse");
        break;
      case Kind::kOther:
        break;
    }
  }
  if (!status_) return false;
  if (has_changes_)
    return stop("body changes of step " + std::to_string(changes_.step()) +
                " with no frame after them");
  if (has_current_) return finish_frame(frame);
  if (cut_short_) {
    cut_short_ = false;
    return stop(
        "the recording ends before its footer (it was cut short: every whole step "
        "before the cut was read)");
  }
  return false;
}

}  // namespace tumble::client
