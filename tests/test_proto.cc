// The API's messages: a frame of 1000 body poses stays well under 100 kB (packed doubles, small
// varint ids), survives a round trip exactly, and the generated service compiles and links.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "tumble/v1/world.grpc.pb.h"
#include "tumble/v1/world.pb.h"

namespace {

// Ids as the server will make them: slot index in the low 32 bits, generation above.
std::uint64_t make_id(std::uint32_t index, std::uint32_t generation) {
  return static_cast<std::uint64_t>(generation) << 32 | index;
}

tumble::v1::Frame thousand_body_frame(bool velocities) {
  tumble::v1::Frame frame;
  frame.set_step(123456);
  frame.set_time(123456 / 60.0);
  for (std::uint32_t i = 0; i < 1000; ++i) {
    frame.add_ids(make_id(i, 1 + i % 3));  // reused slots: generations above 0
    // Values with every bit of the mantissa in use, as positions of tumbling bodies are.
    for (double v : {1.0 / 3 + i, -2.0 / 7 * i, 0.1 * i + 0.5})
      frame.add_positions(v);
    for (double v :
         {0.5477225575051661, 0.5477225575051661, 0.4472135954999579, 0.4472135954999579})
      frame.add_orientations(v);
    if (velocities) {
      for (double v : {0.1 * i, -0.2, 9.81 / 7})
        frame.add_linear_velocities(v);
      for (double v : {1e-3 * i, 2.5, -1.0 / 9})
        frame.add_angular_velocities(v);
    }
  }
  return frame;
}

TEST(Proto, ThousandPosesFitWellUnder100Kilobytes) {
  const tumble::v1::Frame frame = thousand_body_frame(false);
  const std::size_t bytes = frame.ByteSizeLong();
  // 7 doubles a body (56 kB in all) and a 5-byte id: the encoding adds almost nothing.
  EXPECT_LT(bytes, 64'000u);
  EXPECT_GT(bytes, 56'000u);
  // Velocities are asked for separately; with them a frame stays near 110 kB.
  EXPECT_LT(thousand_body_frame(true).ByteSizeLong(), 112'000u);
}

TEST(Proto, FrameRoundTripIsExact) {
  const tumble::v1::Frame frame = thousand_body_frame(true);
  std::string wire;
  ASSERT_TRUE(frame.SerializeToString(&wire));
  tumble::v1::Frame back;
  ASSERT_TRUE(back.ParseFromString(wire));
  ASSERT_EQ(back.ids_size(), 1000);
  EXPECT_EQ(back.ids(999), make_id(999, 1));
  EXPECT_EQ(back.positions(3 * 500 + 1), -2.0 / 7 * 500);
  EXPECT_EQ(back.SerializeAsString(), wire);
}

TEST(Proto, ServiceHasEveryMethodOfTheApi) {
  const google::protobuf::ServiceDescriptor* service =
      tumble::v1::Frame::descriptor()->file()->FindServiceByName("World");
  ASSERT_NE(service, nullptr);
  for (const char* method :
       {"SpawnBodies", "RemoveBodies", "SetBodyState", "ApplyImpulse", "GetBodies", "LoadScene",
        "Control", "GetInfo", "StreamFrames", "Snapshot", "Restore", "Query"})
    EXPECT_NE(service->FindMethodByName(method), nullptr) << method;
  EXPECT_TRUE(service->FindMethodByName("StreamFrames")->server_streaming());
  // The generated server base class links.
  tumble::v1::World::Service base;
  (void)base;
}

}  // namespace
