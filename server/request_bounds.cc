#include "request_bounds.h"

#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/message.h>
#include <google/protobuf/wire_format_lite.h>

#include <algorithm>
#include <vector>

namespace tumble::server {
namespace {

using google::protobuf::Descriptor;
using google::protobuf::FieldDescriptor;
using google::protobuf::internal::WireFormatLite;
using google::protobuf::io::CodedInputStream;

constexpr std::size_t kKiB = 1024, kMiB = 1024 * 1024;

// Bytes per entry of the largest sensible entry of each batch, on the wire: an id is at most 11
// (tag and a 10-byte varint); an impulse at most an id and two vectors (about 70); a state update
// with every field set an id, seven vectors of three or four doubles, three doubles and two
// filter words (about 280); a body spec with every field set and a short name about 420, hull
// points aside; a scene body in JSON about twice that.
constexpr std::size_t kIdBytes = 11, kUpdateBytes = 384, kImpulseBytes = 96, kSpecBytes = 512,
                      kSceneBodyBytes = 1024;
// A joint spec with every field set: two ids, three vectors, ten doubles and their tags (about
// 230); a drive update: an id, a motor and a spring, two flags (about 70).
constexpr std::size_t kJointSpecBytes = 320, kDriveBytes = 96;
// A ray of a query: seven doubles in packed arrays.
constexpr std::size_t kRayBytes = 56;
// Room beyond the per-entry bytes: a few hulls of the most points a hull may have (1024 points
// of three doubles, 24 KiB each) in a batch, the fields of a request that are not entries.
constexpr std::size_t kSlack = kMiB;

// The memory a parsed `type` takes before any of its fields are set.
std::size_t empty_size(const Descriptor& type) {
  const google::protobuf::Message* prototype =
      google::protobuf::MessageFactory::generated_factory()->GetPrototype(&type);
  return prototype != nullptr ? prototype->SpaceUsedLong() : 64;
}

std::size_t scalar_size(const FieldDescriptor& field) {
  switch (field.cpp_type()) {
    case FieldDescriptor::CPPTYPE_BOOL:
      return 1;
    case FieldDescriptor::CPPTYPE_INT32:
    case FieldDescriptor::CPPTYPE_UINT32:
    case FieldDescriptor::CPPTYPE_FLOAT:
    case FieldDescriptor::CPPTYPE_ENUM:
      return 4;
    default:
      return 8;
  }
}

// Entries of a packed field of `length` bytes: varints end in a byte below 0x80.
Result<std::size_t> packed_count(CodedInputStream* in, const FieldDescriptor& field,
                                 std::uint32_t length) {
  const auto wire =
      WireFormatLite::WireTypeForFieldType(static_cast<WireFormatLite::FieldType>(field.type()));
  if (wire == WireFormatLite::WIRETYPE_FIXED64 || wire == WireFormatLite::WIRETYPE_FIXED32) {
    const std::uint32_t width = wire == WireFormatLite::WIRETYPE_FIXED64 ? 8 : 4;
    if (length % width != 0) return Status::error("a packed field's length is not whole entries");
    if (!in->Skip(static_cast<int>(length))) return Status::error("cut short");
    return std::size_t{length / width};
  }
  std::size_t count = 0;
  const void* data = nullptr;
  int size = 0;
  std::uint32_t left = length;
  while (left > 0) {
    if (!in->GetDirectBufferPointer(&data, &size) || size <= 0) return Status::error("cut short");
    const int take = std::min<int>(size, static_cast<int>(left));
    const auto* bytes = static_cast<const unsigned char*>(data);
    for (int i = 0; i < take; ++i)
      count += bytes[i] < 0x80 ? 1 : 0;
    in->Skip(take);
    left -= static_cast<std::uint32_t>(take);
  }
  return count;
}

struct Scanner {
  std::size_t max_parsed, max_top_entries;
  WireScan found;
  std::vector<std::pair<const FieldDescriptor*, std::size_t>> top_counts;

  Status charge(std::size_t bytes) {
    found.parsed_bytes += bytes;
    if (found.parsed_bytes > max_parsed)
      return Status::error(
          "would take more than " + std::to_string(max_parsed) + " bytes once parsed",
          StatusCode::kResourceExhausted);
    return Status::ok();
  }
  Status count_top(const FieldDescriptor& field, std::size_t entries) {
    auto counted = std::find_if(top_counts.begin(), top_counts.end(),
                                [&](const auto& entry) { return entry.first == &field; });
    if (counted == top_counts.end()) counted = top_counts.insert(counted, {&field, 0});
    counted->second += entries;
    found.top_entries = std::max(found.top_entries, counted->second);
    if (max_top_entries != 0 && counted->second > max_top_entries)
      return Status::error(
          field.name() + ": more than " + std::to_string(max_top_entries) + " entries",
          StatusCode::kResourceExhausted);
    return Status::ok();
  }

  // The fields of one message, up to the stream's current limit.
  Status message(CodedInputStream* in, const Descriptor& type, int depth) {
    if (depth > 32) return Status::error("messages nested more than 32 deep");
    while (true) {
      const std::uint32_t tag = in->ReadTag();
      if (tag == 0)
        return in->BytesUntilLimit() == 0 ? Status::ok()
                                          : Status::error("not a " + type.full_name());
      const FieldDescriptor* field =
          type.FindFieldByNumber(static_cast<int>(WireFormatLite::GetTagFieldNumber(tag)));
      const auto wire = WireFormatLite::GetTagWireType(tag);
      const bool top = depth == 0 && field != nullptr && field->is_repeated();
      if (field != nullptr && wire == WireFormatLite::WIRETYPE_LENGTH_DELIMITED) {
        std::uint32_t length = 0;
        if (!in->ReadVarint32(&length) || static_cast<int>(length) < 0 ||
            static_cast<int>(length) > in->BytesUntilLimit())
          return Status::error("a length runs past the end");
        if (field->type() == FieldDescriptor::TYPE_MESSAGE) {
          if (Status s = charge(empty_size(*field->message_type()) +
                                (field->is_repeated() ? 2 * sizeof(void*) : 0));
              !s)
            return s;
          if (top)
            if (Status s = count_top(*field, 1); !s) return s;
          const auto limit = in->PushLimit(static_cast<int>(length));
          if (Status s = message(in, *field->message_type(), depth + 1); !s) return s;
          in->PopLimit(limit);
          continue;
        }
        if (field->is_repeated() && field->cpp_type() != FieldDescriptor::CPPTYPE_STRING) {
          Result<std::size_t> entries = packed_count(in, *field, length);
          if (!entries) return entries.status();
          if (Status s = charge(2 * scalar_size(*field) * entries.value()); !s) return s;
          if (top)
            if (Status s = count_top(*field, entries.value()); !s) return s;
          continue;
        }
        // Strings and bytes: their own length, and a string object.
        if (Status s = charge(length + 32); !s) return s;
        if (top)
          if (Status s = count_top(*field, 1); !s) return s;
        if (!in->Skip(static_cast<int>(length))) return Status::error("cut short");
        continue;
      }
      if (field != nullptr && field->is_repeated()) {
        if (Status s = charge(2 * scalar_size(*field)); !s) return s;
        if (top)
          if (Status s = count_top(*field, 1); !s) return s;
      }
      // Unknown fields are kept by the parser: charged at their size.
      if (field == nullptr)
        if (Status s = charge(16); !s) return s;
      if (wire == WireFormatLite::WIRETYPE_END_GROUP) return Status::error("a stray group end");
      if (!WireFormatLite::SkipField(in, tag)) return Status::error("not a " + type.full_name());
    }
  }
};

}  // namespace

MethodBounds RequestBounds::of(std::string_view method) const {
  const std::size_t slash = method.rfind('/');
  if (slash != std::string_view::npos) method.remove_prefix(slash + 1);
  const std::size_t n = max_bodies;
  auto capped = [&](std::size_t bytes) { return std::min(bytes, max_message_bytes); };
  if (method == "SpawnBodies") return {capped(kSpecBytes * n + kSlack), n};
  if (method == "GetBodies" || method == "RemoveBodies" || method == "StreamFrames")
    return {capped(kIdBytes * n + kKiB), n};
  if (method == "SetBodyState") return {capped(kUpdateBytes * n + kKiB), n};
  if (method == "ApplyImpulse") return {capped(kImpulseBytes * n + kKiB), n};
  // Six numbers and a distance a ray, in packed arrays (kMaxQueryRays).
  // Overlaps' shapes: a few hulls of the most points, as SpawnBodies' slack allows.
  if (method == "Query") return {capped(kRayBytes * kMaxQueryRays + kSlack), 0};
  // A world holds at most two joints a body (scenes/scene.h, kJointsPerBody).
  const std::size_t joints = 2 * n;
  if (method == "CreateJoints") return {capped(kJointSpecBytes * joints + kKiB), joints};
  if (method == "RemoveJoints" || method == "GetJoints")
    return {capped(kIdBytes * joints + kKiB), joints};
  if (method == "SetJointDrives") return {capped(kDriveBytes * joints + kKiB), joints};
  if (method == "LoadScene") return {capped(kSceneBodyBytes * n + kSlack), 0};
  if (method == "Restore") return {max_message_bytes, 0};
  if (method == "Control") return {4 * kKiB, 0};
  return {kKiB, 0};  // GetInfo, Snapshot: empty requests
}

std::size_t RequestBounds::largest() const {
  std::size_t largest = 0;
  for (const char* method :
       {"SpawnBodies", "GetBodies", "SetBodyState", "ApplyImpulse", "CreateJoints", "RemoveJoints",
        "SetJointDrives", "GetJoints", "LoadScene", "Restore", "Control", "Query"})
    largest = std::max(largest, of(method).bytes);
  return largest;
}

Result<WireScan> scan_wire(std::string_view bytes, const Descriptor& type,
                           std::size_t max_parsed_bytes, std::size_t max_top_entries) {
  if (bytes.size() > static_cast<std::size_t>(INT32_MAX))
    return Status::error("more than 2 GiB", StatusCode::kResourceExhausted);
  CodedInputStream in(reinterpret_cast<const std::uint8_t*>(bytes.data()),
                      static_cast<int>(bytes.size()));
  in.SetRecursionLimit(64);
  // A limit over the whole input, so that the end of every message is a limit reached.
  in.PushLimit(static_cast<int>(bytes.size()));
  Scanner scanner{max_parsed_bytes, max_top_entries, {}, {}};
  if (Status s = scanner.charge(empty_size(type)); !s) return s;
  if (Status s = scanner.message(&in, type, 0); !s) return s;
  return scanner.found;
}

}  // namespace tumble::server
