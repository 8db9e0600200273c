#include "recording.h"

#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/util/delimited_message_util.h>

#include <sstream>

namespace tumble::client {
namespace {
constexpr char kMagic[] = "tumble-recording 1\n";
constexpr std::size_t kMagicLength = sizeof kMagic - 1;
}  // namespace

Result<RecordingWriter> RecordingWriter::create(const std::string& path) {
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  if (!file) return Status::error(path + ": cannot create");
  file.write(kMagic, kMagicLength);
  file.flush();
  if (!file) return Status::error(path + ": cannot write");
  return RecordingWriter(std::move(file));
}

Status RecordingWriter::write(const v1::Frame& frame) {
  if (!google::protobuf::util::SerializeDelimitedToOstream(frame, &file_) || !file_.flush())
    return Status::error("recording: cannot write (disk full?)");
  return Status::ok();
}

Result<RecordingReader> RecordingReader::open(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return Status::error(path + ": cannot open");
  std::stringstream bytes;
  bytes << file.rdbuf();
  std::string data = std::move(bytes).str();
  if (data.compare(0, kMagicLength, kMagic) != 0)
    return Status::error(path + ": not a tumble recording (no 'tumble-recording 1' header)");
  RecordingReader reader(std::move(data));
  reader.offset_ = kMagicLength;
  return reader;
}

bool RecordingReader::next(v1::Frame* frame) {
  if (offset_ >= bytes_.size()) return false;
  google::protobuf::io::CodedInputStream input(
      reinterpret_cast<const std::uint8_t*>(bytes_.data() + offset_),
      static_cast<int>(std::min<std::size_t>(bytes_.size() - offset_, INT32_MAX)));
  std::uint32_t length = 0;
  if (!input.ReadVarint32(&length) || length > bytes_.size() - offset_ - input.CurrentPosition()) {
    truncated_ = true;
    offset_ = bytes_.size();
    return false;
  }
  const std::size_t start = offset_ + input.CurrentPosition();
  if (!frame->ParseFromArray(bytes_.data() + start, static_cast<int>(length))) {
    truncated_ = true;
    offset_ = bytes_.size();
    return false;
  }
  offset_ = start + length;
  return true;
}

}  // namespace tumble::client
