// The CLI's text formats for other tools: a JSON line holds what the frame holds (poses, and
// velocities, contacts, statistics, bodies added and removed when present) and its numbers read
// back to the same doubles; CSV has one row per body under its header.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "frame_format.h"

namespace tumble::client {
namespace {

using Json = nlohmann::json;

v1::Frame two_bodies() {
  v1::Frame frame;
  frame.set_step(12);
  frame.set_time(0.2);
  for (std::uint64_t id : {4, 9}) {
    frame.add_ids(id);
    for (double x : {0.1 * id, -1.0 / 3, 7e-300})
      frame.add_positions(x);
    for (double q : {1.0, 0.0, 0.0, 0.0})
      frame.add_orientations(q);
  }
  return frame;
}

TEST(FrameFormat, AJsonLineHoldsThePosesAndTheirExactNumbers) {
  const Json line = Json::parse(frame_to_json_line(two_bodies()));
  EXPECT_EQ(line["step"], 12);
  EXPECT_EQ(line["time"].get<double>(), 0.2);
  ASSERT_EQ(line["bodies"].size(), 2u);
  EXPECT_EQ(line["bodies"][1]["id"], 9);
  EXPECT_EQ(line["bodies"][1]["p"][0].get<double>(), 0.1 * 9);
  EXPECT_EQ(line["bodies"][1]["p"][1].get<double>(), -1.0 / 3);
  EXPECT_EQ(line["bodies"][1]["p"][2].get<double>(), 7e-300);
  EXPECT_FALSE(line["bodies"][0].contains("v"));
  for (const char* absent : {"contacts", "stats", "added", "removed"})
    EXPECT_FALSE(line.contains(absent)) << absent;
}

TEST(FrameFormat, AJsonLineHoldsContactsAndEveryStatistic) {
  v1::Frame frame = two_bodies();
  v1::Contacts* contacts = frame.mutable_contacts();
  contacts->add_body_a(4);
  contacts->add_body_b(9);
  for (double v : {1.0, 2.0, 3.0})
    contacts->add_points(v);
  for (double v : {0.0, 0.0, 1.0})
    contacts->add_normals(v);
  contacts->add_depths(1e-4);
  contacts->add_impulses(0.5);
  // Each field of the statistics its own value, found again under the field's name.
  v1::StepStats* stats = frame.mutable_stats();
  const google::protobuf::Descriptor* descriptor = stats->GetDescriptor();
  const google::protobuf::Reflection* reflection = stats->GetReflection();
  for (int i = 0; i < descriptor->field_count(); ++i) {
    const google::protobuf::FieldDescriptor* field = descriptor->field(i);
    if (field->cpp_type() == google::protobuf::FieldDescriptor::CPPTYPE_UINT32)
      reflection->SetUInt32(stats, field, 100 + i);
    else if (field->cpp_type() == google::protobuf::FieldDescriptor::CPPTYPE_UINT64)
      reflection->SetUInt64(stats, field, (1ull << 40) + i);
    else if (field->cpp_type() == google::protobuf::FieldDescriptor::CPPTYPE_DOUBLE)
      reflection->SetDouble(stats, field, 0.5 + i / 3.0);
    else
      ADD_FAILURE() << field->name() << ": a field that is not a number";
  }
  const Json line = Json::parse(frame_to_json_line(frame));
  ASSERT_EQ(line["contacts"].size(), 1u);
  EXPECT_EQ(line["contacts"][0]["a"], 4);
  EXPECT_EQ(line["contacts"][0]["n"][2].get<double>(), 1.0);
  EXPECT_EQ(line["contacts"][0]["depth"].get<double>(), 1e-4);
  ASSERT_TRUE(line.contains("stats"));
  EXPECT_EQ(line["stats"].size(), static_cast<std::size_t>(descriptor->field_count()));
  for (int i = 0; i < descriptor->field_count(); ++i) {
    const google::protobuf::FieldDescriptor* field = descriptor->field(i);
    ASSERT_TRUE(line["stats"].contains(field->name())) << field->name();
    const Json& value = line["stats"][field->name()];
    if (field->cpp_type() == google::protobuf::FieldDescriptor::CPPTYPE_UINT32)
      EXPECT_EQ(value.get<std::uint32_t>(), 100u + i) << field->name();
    else if (field->cpp_type() == google::protobuf::FieldDescriptor::CPPTYPE_UINT64)
      EXPECT_EQ(value.get<std::uint64_t>(), (1ull << 40) + i) << field->name();
    else
      EXPECT_EQ(value.get<double>(), 0.5 + i / 3.0) << field->name();
  }
  EXPECT_EQ(line["stats"]["solver_bodies"].get<std::uint32_t>(), stats->solver_bodies());
}

TEST(FrameFormat, CsvHasOneRowPerBodyUnderItsHeader) {
  for (const bool velocities : {false, true}) {
    v1::Frame frame = two_bodies();
    for (int k = 0; k < 6; ++k) {
      frame.add_linear_velocities(k);
      frame.add_angular_velocities(-k);
    }
    const std::string header = csv_header(velocities);
    const std::size_t columns = std::count(header.begin(), header.end(), ',') + 1;
    std::istringstream rows(frame_to_csv_rows(frame, velocities));
    std::string row;
    int count = 0;
    while (std::getline(rows, row)) {
      EXPECT_EQ(std::count(row.begin(), row.end(), ',') + 1, static_cast<long>(columns)) << row;
      ++count;
    }
    EXPECT_EQ(count, 2);
  }
}

}  // namespace
}  // namespace tumble::client
