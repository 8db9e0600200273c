// The parts of MCAP (https://mcap.dev/spec, major version 0) that Tumble's recordings use: record
// opcodes, the little-endian encodings and the channels a recording holds. The writer is
// proto/tumble/recording_writer.h, the reader client/recording.h.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

namespace tumble::mcap {

inline constexpr char kMagic[] = "\x89MCAP0\r\n";  // at both ends of the file
inline constexpr std::size_t kMagicSize = 8;

enum Opcode : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kStatistics = 0x0B,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

// The channels of a recording, one per kind of data, with their ids (the schema of each has the
// same id). Each step writes, in this order: its body changes (when there are any), its frame
// (poses and velocities), its contacts and its statistics (when recorded).
struct ChannelInfo {
  std::uint16_t id;
  const char* topic;
  const char* schema;  // the protobuf message, fully qualified
};
inline constexpr ChannelInfo kBodiesChannel{1, "/tumble/bodies", "tumble.v1.BodyChanges"};
inline constexpr ChannelInfo kFramesChannel{2, "/tumble/frames", "tumble.v1.Frame"};
inline constexpr ChannelInfo kContactsChannel{3, "/tumble/contacts", "tumble.v1.Contacts"};
inline constexpr ChannelInfo kStatsChannel{4, "/tumble/stats", "tumble.v1.StepStats"};
inline constexpr ChannelInfo kChannels[] = {kBodiesChannel, kFramesChannel, kContactsChannel,
                                            kStatsChannel};

// Appends little-endian integers and MCAP's length-prefixed strings.
class Bytes {
 public:
  template <class T>
  void put(T value) {
    for (std::size_t i = 0; i < sizeof(T); ++i)
      data_.push_back(static_cast<char>((static_cast<std::uint64_t>(value) >> (8 * i)) & 0xFF));
  }
  void put_string(std::string_view text) {  // also "bytes" fields with a uint32 length
    put(static_cast<std::uint32_t>(text.size()));
    data_.append(text);
  }
  void append(std::string_view raw) { data_.append(raw); }
  const std::string& data() const { return data_; }
  std::string& data() { return data_; }
  std::size_t size() const { return data_.size(); }
  void clear() { data_.clear(); }

 private:
  std::string data_;
};

// A record: opcode, uint64 content length, content.
inline void put_record(Bytes& out, Opcode opcode, std::string_view content) {
  out.put(static_cast<std::uint8_t>(opcode));
  out.put(static_cast<std::uint64_t>(content.size()));
  out.append(content);
}

// Reads little-endian integers from a bounded span; every read says whether it fitted.
class Cursor {
 public:
  Cursor(std::string_view bytes) : bytes_(bytes) {}
  template <class T>
  bool get(T* value) {
    if (bytes_.size() - offset_ < sizeof(T)) return false;
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i)
      v |= static_cast<std::uint64_t>(static_cast<std::uint8_t>(bytes_[offset_ + i])) << (8 * i);
    *value = static_cast<T>(v);
    offset_ += sizeof(T);
    return true;
  }
  bool get_string(std::string_view* text) {
    std::uint32_t length = 0;
    if (!get(&length) || bytes_.size() - offset_ < length) return false;
    *text = bytes_.substr(offset_, length);
    offset_ += length;
    return true;
  }
  bool take(std::size_t length, std::string_view* out) {
    if (bytes_.size() - offset_ < length) return false;
    *out = bytes_.substr(offset_, length);
    offset_ += length;
    return true;
  }
  std::string_view rest() const { return bytes_.substr(offset_); }
  std::size_t offset() const { return offset_; }
  bool at_end() const { return offset_ == bytes_.size(); }

 private:
  std::string_view bytes_;
  std::size_t offset_ = 0;
};

}  // namespace tumble::mcap
