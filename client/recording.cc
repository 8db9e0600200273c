#include "recording.h"

#include "frame_format.h"

#include <google/protobuf/io/coded_stream.h>

#include <sstream>

namespace tumble::client {
namespace {
constexpr std::size_t kMagicLength = sizeof kRecordingMagic - 1;
}  // namespace

Result<RecordingReader> RecordingReader::open(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return Status::error(path + ": cannot open");
  std::stringstream bytes;
  bytes << file.rdbuf();
  std::string data = std::move(bytes).str();
  if (data.compare(0, kMagicLength, kRecordingMagic) != 0)
    return Status::error(path + ": not a tumble recording (no 'tumble-recording 1' header)");
  RecordingReader reader(std::move(data));
  reader.offset_ = kMagicLength;
  return reader;
}

bool RecordingReader::stop(const std::string& why) {
  status_ = Status::error("byte " + std::to_string(offset_) + " (frame " +
                          std::to_string(frames_ + 1) + "): " + why);
  offset_ = bytes_.size();
  return false;
}

bool RecordingReader::next(v1::Frame* frame) {
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

}  // namespace tumble::client
