// Spawns a body in a running server and reads it back, with an installed Tumble's client library
// (which links none of the engine); and asks for a recording that is not there.
#include <cstdio>

#include "tumble/client.h"
#include "tumble/recording.h"

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  tumble::client::Client client = tumble::client::Client::connect({.address = argv[1]}).value();
  tumble::v1::BodySpec ball;
  ball.mutable_shape()->mutable_sphere()->set_radius(0.25);
  ball.mutable_position()->set_z(3);
  auto ids = client.spawn({ball});
  if (!ids) return std::fprintf(stderr, "spawn: %s\n", ids.status().message().c_str()), 1;
  auto bodies = client.bodies(ids.value());
  if (!bodies) return 1;
  std::printf("body %llu at z = %.2f m\n", static_cast<unsigned long long>(ids.value()[0]),
              bodies.value().states(0).position().z());
  auto missing = tumble::client::RecordingReader::open("/nonexistent.mcap");
  std::printf("%s\n", missing.ok() ? "opened?" : missing.error().c_str());
  return missing.ok() ? 1 : 0;
}
