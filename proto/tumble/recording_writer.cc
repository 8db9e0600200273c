#include "tumble/recording_writer.h"

#include <google/protobuf/util/delimited_message_util.h>

namespace tumble {

Result<RecordingWriter> RecordingWriter::create(const std::string& path) {
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  if (!file) return Status::error(path + ": cannot create");
  file.write(kRecordingMagic, sizeof kRecordingMagic - 1);
  file.flush();
  if (!file) return Status::error(path + ": cannot write");
  return RecordingWriter(std::move(file));
}

Status RecordingWriter::write(const v1::Frame& frame) {
  if (!google::protobuf::util::SerializeDelimitedToOstream(frame, &file_) || !file_.flush())
    return Status::error("recording: cannot write (disk full?)");
  return Status::ok();
}

}  // namespace tumble
