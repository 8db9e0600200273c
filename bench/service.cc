// The service end to end over loopback TCP: a server in this process steps 1000 bodies; N
// subscribers (each its own connection and thread) stream every frame. Reports the step rate with
// and without subscribers, the frames each subscriber received per second, and the latency from
// the end of a step to the frame's arrival (p50, p99), with the world paced at 1 kHz (dt 1 ms,
// real time) and running flat out; and with subscribers that never read. Usage: bench_service
// [seconds per row, default 3] [step threads, default 1: on a 2-core machine the other core serves
// the streams]
#include <grpcpp/grpcpp.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <thread>
#include <vector>

#include "drifting_spheres.h"
#include "scenes/scene.h"
#include "service.h"

namespace {

using namespace tumble;
using Clock = std::chrono::steady_clock;
using bench::drifting_spheres;
using bench::unix_ns;

struct Row {
  double step_rate = 0;       // steps per second of wall time
  double frames_per_sub = 0;  // frames per second, mean over subscribers
  double p50_ms = 0, p99_ms = 0;
};

// `stalled`: the subscribers open their streams and never read one frame.
Row measure(const SceneDef& scene, double real_time_factor, int subscribers, bool stalled,
            double seconds) {
  server::WorldHost host(make_world(scene).value(), scene.dt, real_time_factor);
  server::WorldService service(host, {}, scene);
  grpc::ServerBuilder builder;
  int port = 0;
  builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), &port);
  service.register_on(builder);
  std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
  const std::string address = "127.0.0.1:" + std::to_string(port);

  std::atomic<bool> stop{false};
  std::mutex mutex;
  std::vector<double> latencies_ms;
  std::vector<std::uint64_t> received(subscribers, 0);
  std::vector<std::thread> readers;
  std::atomic<int> connected{0};
  for (int s = 0; s < subscribers; ++s) {
    readers.emplace_back([&, s] {
      grpc::ChannelArguments arguments;
      arguments.SetInt("grpc.use_local_subchannel_pool", 1);  // a connection of its own
      auto stub = v1::World::NewStub(
          grpc::CreateCustomChannel(address, grpc::InsecureChannelCredentials(), arguments));
      grpc::ClientContext context;
      auto reader = stub->StreamFrames(&context, {});
      v1::Frame frame;
      std::vector<double> mine;
      bool first = true;
      if (stalled) {
        ++connected;
        while (!stop)
          std::this_thread::sleep_for(std::chrono::milliseconds(10));
        context.TryCancel();
        return;
      }
      while (!stop && reader->Read(&frame)) {
        if (first) {
          first = false;
          ++connected;
          continue;
        }
        mine.push_back((unix_ns() - frame.stepped_at_unix_ns()) * 1e-6);
        ++received[s];
      }
      context.TryCancel();
      reader->Finish();
      std::lock_guard lock(mutex);
      latencies_ms.insert(latencies_ms.end(), mine.begin(), mine.end());
    });
  }
  for (int i = 0; i < 1000 && connected < subscribers; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  for (int i = 0; i < 1000 && host.status().subscribers < static_cast<std::size_t>(subscribers);
       ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  const std::uint64_t step0 = host.status().step;
  std::fill(received.begin(), received.end(), 0);
  const auto start = Clock::now();
  host.play();
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  const std::uint64_t steps = host.status().step - step0;
  const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  std::vector<std::uint64_t> counts = received;
  stop = true;
  host.pause();
  service.shut_down();
  server->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(2));
  for (std::thread& t : readers)
    t.join();

  Row row;
  row.step_rate = steps / elapsed;
  for (std::uint64_t c : counts)
    row.frames_per_sub += c / elapsed / std::max(1, subscribers);
  if (!latencies_ms.empty()) {
    std::sort(latencies_ms.begin(), latencies_ms.end());
    row.p50_ms = latencies_ms[latencies_ms.size() / 2];
    row.p99_ms = latencies_ms[latencies_ms.size() * 99 / 100];
  }
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::atof(argv[1]) : 3.0;
  const SceneDef scene = drifting_spheres(argc > 2 ? std::atoi(argv[2]) : 1);
  // The bare engine on this machine now, for the flat-out rows' ceiling.
  {
    World world = make_world(scene).value();
    const auto start = Clock::now();
    int steps = 0;
    while (std::chrono::duration<double>(Clock::now() - start).count() < 1.0) {
      world.step(scene.dt);
      ++steps;
    }
    std::printf("bench_service: %s, %d step thread(s); the engine alone: %.0f steps/s\n",
                scene.name.c_str(), scene.world.threads,
                steps / std::chrono::duration<double>(Clock::now() - start).count());
  }
  std::printf("%-9s %-12s %11s %11s %9s %9s\n", "pace", "subscribers", "steps/s", "frames/s/sub",
              "p50 ms", "p99 ms");
  struct Case {
    int subscribers;
    bool stalled;
  };
  for (double factor : {1.0, 0.0}) {
    for (Case c :
         {Case{0, false}, {1, false}, {4, false}, {8, false}, {16, false}, {1, true}, {8, true}}) {
      const Row row = measure(scene, factor, c.subscribers, c.stalled, seconds);
      const std::string who = std::to_string(c.subscribers) + (c.stalled ? " stalled" : "");
      std::printf("%-9s %-12s %11.0f %11.0f %9.3f %9.3f\n", factor > 0 ? "1 kHz" : "flat out",
                  who.c_str(), row.step_rate, row.frames_per_sub, row.p50_ms, row.p99_ms);
      std::fflush(stdout);
    }
  }
  return 0;
}
