// What a request costs the caller, end to end over loopback: a running tumble-server (any build,
// so that two can be compared in one sitting) answers GetInfo, GetBodies of 10 ids and a
// SpawnBodies of one sphere plus its RemoveBodies, one call at a time from one client, for
// `seconds` each. Prints calls per second and the p50 and p99 round trip. Usage:
// bench_unary_calls HOST:PORT [seconds, default 3]
#include <grpcpp/grpcpp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "tumble/v1/world.grpc.pb.h"

namespace {

using Clock = std::chrono::steady_clock;

void measure(const char* name, double seconds, const std::function<bool()>& call) {
  std::vector<double> ms;
  const auto start = Clock::now();
  while (std::chrono::duration<double>(Clock::now() - start).count() < seconds) {
    const auto before = Clock::now();
    if (!call()) {
      std::printf("%-22s failed\n", name);
      return;
    }
    ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - before).count());
  }
  const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  std::sort(ms.begin(), ms.end());
  std::printf("%-22s %9.0f %9.3f %9.3f\n", name, ms.size() / elapsed, ms[ms.size() / 2],
              ms[ms.size() * 99 / 100]);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_unary_calls HOST:PORT [seconds]\n");
    return 2;
  }
  const double seconds = argc > 2 ? std::atof(argv[2]) : 3.0;
  auto channel = grpc::CreateChannel(argv[1], grpc::InsecureChannelCredentials());
  if (!channel->WaitForConnected(std::chrono::system_clock::now() + std::chrono::seconds(10))) {
    std::fprintf(stderr, "bench_unary_calls: cannot connect to %s\n", argv[1]);
    return 1;
  }
  auto stub = tumble::v1::World::NewStub(channel);
  std::vector<std::uint64_t> ids;
  {
    grpc::ClientContext context;
    tumble::v1::GetBodiesResponse bodies;
    if (!stub->GetBodies(&context, {}, &bodies).ok()) return 1;
    for (int i = 0; i < bodies.states_size() && ids.size() < 10; ++i)
      ids.push_back(bodies.states(i).id());
  }
  std::printf("%-22s %9s %9s %9s\n", "call", "calls/s", "p50 ms", "p99 ms");
  measure("GetInfo", seconds, [&] {
    grpc::ClientContext context;
    tumble::v1::GetInfoResponse info;
    return stub->GetInfo(&context, {}, &info).ok();
  });
  tumble::v1::GetBodiesRequest ten;
  for (std::uint64_t id : ids)
    ten.add_ids(id);
  measure("GetBodies of 10", seconds, [&] {
    grpc::ClientContext context;
    tumble::v1::GetBodiesResponse bodies;
    return stub->GetBodies(&context, ten, &bodies).ok();
  });
  tumble::v1::SpawnBodiesRequest spawn;
  tumble::v1::BodySpec* ball = spawn.add_bodies();
  ball->mutable_shape()->mutable_sphere()->set_radius(0.1);
  ball->mutable_position()->set_z(100);
  measure("SpawnBodies + Remove", seconds, [&] {
    grpc::ClientContext spawn_context;
    tumble::v1::SpawnBodiesResponse spawned;
    if (!stub->SpawnBodies(&spawn_context, spawn, &spawned).ok()) return false;
    grpc::ClientContext remove_context;
    tumble::v1::RemoveBodiesRequest remove;
    remove.add_ids(spawned.ids(0));
    tumble::v1::RemoveBodiesResponse removed;
    return stub->RemoveBodies(&remove_context, remove, &removed).ok();
  });
  return 0;
}
