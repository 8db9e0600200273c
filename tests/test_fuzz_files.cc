// Issue 17: hostile files. Scene JSON, snapshots and recordings, damaged at the byte level and
// crafted at the field level (hostile numbers, wrong types, huge counts). Each is refused with a
// message, or accepted and then steps to a finite world within its limits; none crashes or hangs.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include <google/protobuf/util/message_differencer.h>
#include "frame_format.h"
#include "fuzz_snapshot.h"
#include "fuzz_support.h"
#include "recording.h"
#include "scene_runner.h"
#include "snapshot.h"

#include <set>

#include "tumble/mcap.h"
#include "tumble/v1/snapshot.pb.h"

namespace tumble {
namespace {

using Json = nlohmann::json;
using testing::FuzzTally;
using testing::Hostile;

void print(const char* what, const FuzzTally& t) {
  std::printf("fuzz %s: %llu inputs, %llu accepted, %llu refused, %llu poisoned\n", what,
              static_cast<unsigned long long>(t.tried), static_cast<unsigned long long>(t.accepted),
              static_cast<unsigned long long>(t.refused),
              static_cast<unsigned long long>(t.poisoned));
}

// A world that was accepted must step and stay sound; says what went wrong.
std::string steps_soundly(World& world, double dt) {
  for (int k = 0; k < 3; ++k) {
    if (Status s = world.step(dt); !s) return "step " + std::to_string(k) + ": " + s.message();
    for (std::uint32_t slot = 0; slot < world.slot_count(); ++slot) {
      const BodyView body = world.body(world.id_at(slot));
      if (!body) continue;
      if (Status s = check_limits(body, world.settings().limits); !s)
        return "after step " + std::to_string(k) + ", slot " + std::to_string(slot) + ": " +
               s.message();
    }
  }
  return "";
}

// Somewhere in `json`, one value replaced by a hostile one, a key removed or added, or an array
// made long.
void craft(Hostile& h, Json* json) {
  Json* node = json;
  for (int depth = 0; depth < 6 && (node->is_object() || node->is_array()) && !node->empty();
       ++depth) {
    if (h.chance(0.25)) break;
    auto it = node->begin();
    std::advance(it, static_cast<long>(h.rng().uniform() * node->size()));
    node = &*it;
  }
  switch (h.integer(0, 7)) {
    case 0:
    case 1: {
      const double v = h.special();
      *node = std::isfinite(v) ? Json(v) : Json(h.chance(0.5) ? 1e308 : -1e308);
      break;
    }
    case 2:
      *node = h.chance(0.5) ? Json("text") : Json(nullptr);
      break;
    case 3:
      *node = Json::array({1, 2});
      break;
    case 4:
      if (node->is_object() && !node->empty()) node->erase(node->begin());
      break;
    case 5:
      if (node->is_object()) (*node)["unknown_field"] = 1;
      break;
    case 6:
      if (node->is_array() && !node->empty())
        for (int k = h.integer(1, 200); k > 0; --k)
          node->push_back(node->front());
      break;
    default:
      *node = h.chance(0.5) ? Json(-1) : Json(static_cast<std::int64_t>(1) << 62);
  }
}

TEST(FuzzFiles, SceneJson) {
  Hostile h(17);
  const std::string base(default_scene_json());
  const Json parsed = Json::parse(base);
  FuzzTally tally;
  for (int i = 0; i < 3000; ++i) {
    std::string text;
    if (h.chance(0.5)) {
      text = h.mutate(base);
    } else {
      Json json = parsed;
      for (int k = h.integer(1, 3); k > 0; --k)
        craft(h, &json);
      text = json.dump();
    }
    ++tally.tried;
    Result<SceneDef> scene = parse_scene(text);
    if (!scene) {
      ++tally.refused;
      EXPECT_FALSE(scene.error().empty());
      continue;
    }
    Result<World> world = make_world(scene.value());
    if (!world) {
      ++tally.refused;
      continue;
    }
    ++tally.accepted;
    if (const std::string wrong = steps_soundly(world.value(), scene.value().dt); !wrong.empty()) {
      ++tally.poisoned;
      ADD_FAILURE() << "scene " << i << " was accepted but stepped into an unsound world (" << wrong
                    << "):\n"
                    << text;
    }
  }
  // Nesting deep enough to overflow a recursive parser's stack.
  const std::string deep = std::string(200000, '[') + std::string(200000, ']');
  EXPECT_FALSE(parse_scene(deep).ok());
  ++tally.tried;
  ++tally.refused;
  print("scene json", tally);
  EXPECT_EQ(tally.poisoned, 0u);
  EXPECT_GT(tally.accepted, 200u);
  EXPECT_GT(tally.refused, 300u);
}

std::string landed_pile_snapshot(const SceneDef& scene = pile_scene(20)) {
  World world = make_world(scene).value();
  for (int k = 0; k < 40; ++k)
    EXPECT_TRUE(world.step(1.0 / 60).is_ok());
  server::SavedWorld saved;
  saved.settings = world.settings();
  saved.state = world.save_state();
  saved.dt = 1.0 / 60;
  for (std::uint32_t slot = 0; slot < world.slot_count(); ++slot) {
    saved.ids.push_back(world.id_at(slot).is_valid() ? slot + 1 : 0);
    saved.colours.push_back(0xffffffffu);
  }
  saved.next_id = world.slot_count() + 1;
  return server::encode_snapshot(saved);
}

// Damaged snapshots of `good`, counted; every accepted one must step soundly.
FuzzTally fuzz_snapshots(Hostile& h, const std::string& good, int count) {
  v1::snapshot::WorldSnapshot parsed;
  EXPECT_TRUE(parsed.ParseFromString(good));
  EXPECT_GT(World::state_sizes(parsed.engine_state()).value().contact_pairs, 0u);
  FuzzTally tally;
  for (int i = 0; i < count; ++i) {
    const std::string bytes = testing::damaged_snapshot(h, good);
    ++tally.tried;
    Result<server::SavedWorld> saved = server::decode_snapshot(bytes);
    Result<World> world = saved ? World::from_state(saved.value().settings, saved.value().state)
                                : Result<World>(saved.status());
    if (!world) {
      ++tally.refused;
      EXPECT_FALSE(world.error().empty());
      continue;
    }
    ++tally.accepted;
    if (const std::string wrong = steps_soundly(world.value(), saved.value().dt); !wrong.empty()) {
      ++tally.poisoned;
      ADD_FAILURE() << "snapshot " << i
                    << " was accepted but stepped into an unsound world: " << wrong;
    }
  }
  return tally;
}

TEST(FuzzFiles, Snapshots) {
  Hostile h(18);
  const FuzzTally tally = fuzz_snapshots(h, landed_pile_snapshot(), 3000);
  print("snapshots", tally);
  EXPECT_EQ(tally.poisoned, 0u);
  EXPECT_GT(tally.accepted, 100u);
  EXPECT_GT(tally.refused, 1000u);
}

// A pile of bodies of parts: hostile numbers over their parts' poses and shapes, their counts and
// types (a part that says it is a compound, a plane or a mesh).
TEST(FuzzFiles, SnapshotsOfCompounds) {
  Hostile h(19);
  const FuzzTally tally = fuzz_snapshots(h, landed_pile_snapshot(compound_pile_scene(12)), 1500);
  print("snapshots of compounds", tally);
  EXPECT_EQ(tally.poisoned, 0u);
  EXPECT_GT(tally.accepted, 50u);
  EXPECT_GT(tally.refused, 500u);
}

// A recording splits each frame into its channels (recording_writer.h); reading puts it back
// together. Every field of Frame is set here, so a field the writer forgot would show.
TEST(Recording, EveryFieldOfEveryFrameComesBackFromTheFile) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("tumble-recording-" + std::to_string(getpid()) + ".mcap"))
                               .string();
  std::vector<v1::Frame> written;
  for (int k = 0; k < 3; ++k) {
    v1::Frame frame;
    frame.set_step(7 + k);
    frame.set_time(0.25 * k);
    for (int b = 0; b < 2; ++b) {
      frame.add_ids(10 + b);
      for (int c = 0; c < 3; ++c) {
        frame.add_positions(b + 0.5 * c + k);
        frame.add_linear_velocities(-c);
        frame.add_angular_velocities(c * 0.125);
      }
      for (double q : {1.0, 0.0, 0.0, 0.0})
        frame.add_orientations(q);
    }
    v1::Contacts* contacts = frame.mutable_contacts();
    contacts->add_body_a(10);
    contacts->add_body_b(11);
    for (double v : {0.0, 0.5, 1.0})
      contacts->add_points(v), contacts->add_normals(v);
    contacts->add_depths(1e-3);
    contacts->add_impulses(2.5);
    frame.mutable_stats()->set_step(7 + k);
    frame.mutable_stats()->set_pairs(3);
    frame.set_dropped(k);
    frame.set_stepped_at_unix_ns(1700000000000000000ull + k);
    if (k == 0)
      for (std::uint64_t id : {10, 11}) {
        v1::BodyDescription* body = frame.add_added();
        body->set_id(id);
        body->mutable_shape()->mutable_sphere()->set_radius(0.5);
        body->set_mass(2);
      }
    if (k == 2) frame.add_removed(12);
    v1::JointStates* joints = frame.mutable_joints();
    joints->add_ids(20);
    joints->add_positions(0.5 * k);
    joints->add_speeds(-1);
    joints->add_efforts(3);
    for (double v : {0.0, 0.5, 1.0}) {
      joints->add_forces(v);
      joints->add_torques(-v);
      joints->add_anchors(2 * v);
      joints->add_axes(v == 1.0 ? 1.0 : 0.0);
    }
    if (k == 0) {
      v1::JointDescription* joint = frame.add_joints_added();
      joint->set_id(20);
      joint->mutable_spec()->set_kind(v1::JOINT_KIND_HINGE);
      joint->mutable_spec()->set_a(10);
    }
    if (k == 2) frame.add_joints_removed(21);
    if (k == 1) frame.set_changes_only(true);
    written.push_back(frame);
  }
  // Every field of Frame is set in some frame above.
  std::set<std::string> set_fields;
  for (const v1::Frame& frame : written) {
    std::vector<const google::protobuf::FieldDescriptor*> fields;
    frame.GetReflection()->ListFields(frame, &fields);
    for (const auto* field : fields)
      set_fields.insert(field->name());
  }
  EXPECT_EQ(set_fields.size(), static_cast<std::size_t>(v1::Frame::descriptor()->field_count()));
  {
    client::Result<client::RecordingWriter> writer = client::RecordingWriter::create(path);
    ASSERT_TRUE(writer.ok()) << writer.error();
    for (const v1::Frame& frame : written)
      ASSERT_TRUE(writer.value().write(frame).is_ok());
    ASSERT_TRUE(writer.value().finish().is_ok());
  }
  client::Result<client::RecordingReader> reader = client::RecordingReader::open(path);
  ASSERT_TRUE(reader.ok()) << reader.error();
  v1::Frame frame;
  for (const v1::Frame& expected : written) {
    ASSERT_TRUE(reader.value().next(&frame)) << reader.value().status().message();
    EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(frame, expected))
        << frame.ShortDebugString() << "\n"
        << expected.ShortDebugString();
  }
  EXPECT_FALSE(reader.value().next(&frame));
  EXPECT_TRUE(reader.value().status().is_ok()) << reader.value().status().message();
  std::filesystem::remove(path);
}

TEST(FuzzFiles, Recordings) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("tumble-fuzz-" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const std::string good_path = (dir / "good.rec").string();
  {
    client::Result<client::RecordingWriter> writer = client::RecordingWriter::create(good_path);
    ASSERT_TRUE(writer.ok()) << writer.error();
    for (int k = 0; k < 20; ++k) {
      v1::Frame frame;
      frame.set_step(k);
      frame.set_time(k / 60.0);
      for (int b = 0; b < 5; ++b) {
        frame.add_ids(b + 1);
        for (int c = 0; c < 3; ++c)
          frame.add_positions(b + c + k);
        for (double q : {1.0, 0.0, 0.0, 0.0})
          frame.add_orientations(q);
      }
      ASSERT_TRUE(writer.value().write(frame).is_ok());
    }
  }
  std::string good;
  {
    std::FILE* file = std::fopen(good_path.c_str(), "rb");
    ASSERT_NE(file, nullptr);
    char buffer[4096];
    for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, file)) > 0;)
      good.append(buffer, n);
    std::fclose(file);
  }
  Hostile h(19);
  FuzzTally tally;
  const std::string path = (dir / "damaged.rec").string();
  for (int i = 0; i < 1000; ++i) {
    std::string bytes = h.mutate(good);
    if (h.chance(0.2)) {  // a record length that claims far more than the file holds
      const std::size_t at =
          h.chance(0.5)
              ? mcap::kMagicSize + 1
              : static_cast<std::size_t>(h.integer(0, static_cast<int>(bytes.size()) - 1));
      if (bytes.size() > at + 8) bytes.replace(at, 8, "\xff\xff\xff\xff\xff\xff\xff\x0f");
    }
    {
      std::FILE* file = std::fopen(path.c_str(), "wb");
      ASSERT_NE(file, nullptr);
      std::fwrite(bytes.data(), 1, bytes.size(), file);
      std::fclose(file);
    }
    ++tally.tried;
    client::Result<client::RecordingReader> reader = client::RecordingReader::open(path);
    if (!reader) {
      ++tally.refused;
      continue;
    }
    v1::Frame frame;
    int frames = 0;
    while (reader.value().next(&frame)) {
      ASSERT_LE(++frames, static_cast<int>(bytes.size())) << "more frames than the file holds";
      // What replay prints: under AddressSanitizer (make test-sanitize) a frame whose arrays
      // do not match its ids would be read out of bounds here.
      EXPECT_FALSE(client::frame_to_json_line(frame).empty());
      client::frame_to_csv_rows(frame, true);
    }
    (reader.value().status() ? tally.accepted : tally.refused)++;
  }
  std::filesystem::remove_all(dir);
  print("recordings", tally);
  EXPECT_GT(tally.accepted, 10u);
  EXPECT_GT(tally.refused, 100u);
}

// Issue 31 (6): crafted recordings that replay read out of bounds (a frame of 100,000 ids and no
// positions; 3 ids, 3 position values, one orientation value; contact arrays of unequal
// lengths), a length of 2^32 + n read as n, and bytes that are not a frame called a recording
// cut short. Each is refused, naming the frame and what is wrong.
TEST(FuzzFiles, CraftedRecordingsAreRefusedNamingWhatIsWrong) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("tumble-crafted-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string header = "tumble-recording 1\n";
  auto varint = [](std::uint64_t value) {
    std::string out;
    while (value >= 0x80) {
      out += static_cast<char>((value & 0x7f) | 0x80);
      value >>= 7;
    }
    out += static_cast<char>(value);
    return out;
  };
  auto framed = [&](const v1::Frame& frame) {
    const std::string bytes = frame.SerializeAsString();
    return varint(bytes.size()) + bytes;
  };
  v1::Frame sound;
  sound.set_step(1);
  sound.add_ids(7);
  for (double v : {0.0, 0.0, 1.0})
    sound.add_positions(v);
  for (double v : {1.0, 0.0, 0.0, 0.0})
    sound.add_orientations(v);
  v1::Frame no_positions;
  for (int i = 0; i < 100000; ++i)
    no_positions.add_ids(i + 1);
  v1::Frame short_orientations;
  for (int i = 0; i < 3; ++i) {
    short_orientations.add_ids(i + 1);
    short_orientations.add_positions(i);
  }
  short_orientations.add_orientations(1);
  v1::Frame unequal_contacts = sound;
  unequal_contacts.mutable_contacts()->add_body_a(7);
  unequal_contacts.mutable_contacts()->add_body_b(7);
  for (int k = 0; k < 3; ++k) {
    unequal_contacts.mutable_contacts()->add_points(0);
    unequal_contacts.mutable_contacts()->add_normals(0);
  }
  const std::string sound_bytes = sound.SerializeAsString();
  struct Crafted {
    const char* what;
    std::string bytes;
    const char* named;
  };
  const Crafted crafted[] = {
      {"100,000 ids, no positions", framed(sound) + framed(no_positions),
       "(frame 2): positions: 0 values for 100000 bodies"},
      {"3 ids, 3 positions, 1 orientation", framed(short_orientations),
       "(frame 1): positions: 3 values for 3 bodies"},
      {"contacts of unequal lengths", framed(unequal_contacts),
       "contacts.depths: 0 values for 1 contacts"},
      {"a length of 2^32 + n", varint((1ull << 32) + sound_bytes.size()) + sound_bytes,
       "a frame of 4294967"},
      {"bytes that are not a frame", framed(sound) + varint(4) + std::string("\xff\xff\xff\xff"),
       "(frame 2): not a frame"},
      {"a length cut off", framed(sound) + "\xff", "ends inside a frame's length"},
  };
  const std::string path = (dir / "crafted.rec").string();
  for (const Crafted& c : crafted) {
    {
      std::ofstream file(path, std::ios::binary | std::ios::trunc);
      file << header << c.bytes;
    }
    client::Result<client::RecordingReader> reader = client::RecordingReader::open(path);
    ASSERT_TRUE(reader) << c.what;
    v1::Frame frame;
    while (reader.value().next(&frame))
      client::frame_to_json_line(frame);
    EXPECT_FALSE(reader.value().status()) << c.what;
    EXPECT_NE(reader.value().status().message().find(c.named), std::string::npos)
        << c.what << ": " << reader.value().status().message();
  }
  {
    std::ofstream file(path, std::ios::binary | std::ios::trunc);
    file << header << framed(sound) << framed(sound);
  }
  client::Result<client::RecordingReader> whole = client::RecordingReader::open(path);
  ASSERT_TRUE(whole);
  v1::Frame frame;
  while (whole.value().next(&frame)) {
  }
  EXPECT_TRUE(whole.value().status()) << whole.value().status().message();
  EXPECT_EQ(whole.value().frames(), 2u);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace tumble
