// The service under load, over loopback TCP: 16 clients spawn and remove batches while 4 stream;
// every spawned body reaches every streamer and no frame ever shows part of a batch. A streamer
// that never reads holds up neither the world nor memory.
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <atomic>
#include <condition_variable>
#include <map>
#include <mutex>
#include <set>
#include <thread>
#include <unordered_map>

#include "heap_in_use.h"
#include "scene_runner.h"
#include "service.h"

namespace tumble::server {
namespace {

using namespace std::chrono_literals;
using testing::heap_in_use;

class LoopbackServer {
 public:
  LoopbackServer(SceneDef scene, double real_time_factor)
      : host_(make_world(scene).value(), scene.dt, real_time_factor),
        service_(host_, {.max_bodies = 100000, .token = "", .world = {}}, scene) {
    grpc::ServerBuilder builder;
    builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), &port_);
    service_.register_on(builder);
    server_ = builder.BuildAndStart();
  }
  ~LoopbackServer() {
    service_.shut_down();
    server_->Shutdown(std::chrono::system_clock::now() + 5s);
  }
  std::unique_ptr<v1::World::Stub> stub() const {
    return v1::World::NewStub(grpc::CreateChannel("127.0.0.1:" + std::to_string(port_),
                                                  grpc::InsecureChannelCredentials()));
  }
  WorldHost& host() { return host_; }

 private:
  WorldHost host_;
  WorldService service_;
  int port_ = 0;
  std::unique_ptr<grpc::Server> server_;
};

// What the streamers have seen: each body id, by streamer.
struct Sightings {
  std::mutex mutex;
  std::condition_variable changed;
  std::vector<std::set<std::uint64_t>> seen;
  bool all_saw(const std::vector<std::uint64_t>& ids) {
    for (const auto& streamer : seen)
      for (std::uint64_t id : ids)
        if (!streamer.contains(id)) return false;
    return true;
  }
};

constexpr int kSpawners = 16, kStreamers = 4, kBatchesEach = 6, kBatchSize = 4;

TEST(ServiceStress, SpawnersAndStreamersTogether) {
  LoopbackServer server(pile_scene(8), 0);
  server.host().play();
  Sightings sightings;
  sightings.seen.resize(kStreamers);
  std::atomic<bool> done{false};
  std::atomic<int> torn_frames{0}, frames_read{0};

  std::vector<std::thread> streamers;
  for (int s = 0; s < kStreamers; ++s) {
    streamers.emplace_back([&, s] {
      auto stub = server.stub();
      grpc::ClientContext context;
      auto reader = stub->StreamFrames(&context, {});
      std::unordered_map<std::uint64_t, std::uint32_t> batch_of;  // id -> batch tag (colour)
      v1::Frame frame;
      while (!done && reader->Read(&frame)) {
        ++frames_read;
        for (const v1::BodyDescription& d : frame.added())
          batch_of[d.id()] = d.color();
        std::map<std::uint32_t, int> members;  // tag -> bodies of that batch in this frame
        for (std::uint64_t id : frame.ids())
          if (auto tag = batch_of.find(id); tag != batch_of.end() && tag->second != 0)
            ++members[tag->second];
        for (const auto& [tag, count] : members)
          if (count != kBatchSize) ++torn_frames;
        std::lock_guard lock(sightings.mutex);
        sightings.seen[s].insert(frame.ids().begin(), frame.ids().end());
        sightings.changed.notify_all();
      }
      context.TryCancel();
      reader->Finish();
    });
  }

  std::atomic<int> failures{0}, batches_seen{0};
  std::vector<std::thread> spawners;
  for (int c = 0; c < kSpawners; ++c) {
    spawners.emplace_back([&, c] {
      auto stub = server.stub();
      for (int b = 0; b < kBatchesEach; ++b) {
        v1::SpawnBodiesRequest request;
        for (int k = 0; k < kBatchSize; ++k) {
          v1::BodySpec* spec = request.add_bodies();
          spec->mutable_shape()->mutable_sphere()->set_radius(0.1);
          spec->mutable_position()->set_x(c * 2.0 + k * 0.3);
          spec->mutable_position()->set_y(40 + b);
          spec->mutable_position()->set_z(5);
          spec->set_color(static_cast<std::uint32_t>(c * 100 + b + 1));  // the batch's tag
        }
        grpc::ClientContext spawn_context;
        v1::SpawnBodiesResponse spawned;
        if (!stub->SpawnBodies(&spawn_context, request, &spawned).ok()) {
          ++failures;
          return;
        }
        const std::vector<std::uint64_t> ids(spawned.ids().begin(), spawned.ids().end());
        {  // held until every streamer has seen the whole batch (bounded)
          std::unique_lock lock(sightings.mutex);
          if (sightings.changed.wait_for(lock, 60s, [&] { return sightings.all_saw(ids); }))
            ++batches_seen;
        }
        v1::RemoveBodiesRequest remove;
        remove.mutable_ids()->Add(ids.begin(), ids.end());
        grpc::ClientContext remove_context;
        v1::RemoveBodiesResponse removed;
        if (!stub->RemoveBodies(&remove_context, remove, &removed).ok()) ++failures;
      }
    });
  }
  for (std::thread& t : spawners)
    t.join();
  done = true;
  {
    // Streams end at their next frame; one more change makes sure a paused world sends one.
    v1::SpawnBodiesRequest poke;
    poke.add_bodies()->mutable_shape()->mutable_sphere()->set_radius(0.1);
    grpc::ClientContext context;
    v1::SpawnBodiesResponse response;
    server.stub()->SpawnBodies(&context, poke, &response);
  }
  for (std::thread& t : streamers)
    t.join();
  server.host().pause();
  EXPECT_EQ(failures, 0);
  EXPECT_EQ(batches_seen, kSpawners * kBatchesEach);  // every spawned body reached every streamer
  EXPECT_EQ(torn_frames, 0);                          // no frame showed part of a batch
  EXPECT_GT(frames_read, kStreamers);
  EXPECT_EQ(server.host().status().bodies, 9u + 1u);  // all batches removed; the scene and poke
}

// A streamer asking for velocities and contacts of 1000 bodies (about 100 kB a frame) that never
// reads: 2000 steps run, and the heap grows by far less than the 200 MB a queue of frames would.
TEST(ServiceStress, AStreamerThatNeverReadsHoldsNothingUp) {
  SceneDef scene;
  scene.world.gravity = Vec3::Zero();  // floating spheres: cheap steps, big frames
  for (int i = 0; i < 1000; ++i) {
    BodyDef ball;
    ball.shape = SphereDef{0.2};
    ball.position = Vec3(i % 10, (i / 10) % 10, i / 100);
    ball.linear_velocity = Vec3(0, 0, 0.01);
    scene.bodies.push_back(ball);
  }
  scene.world.solver.sleeping = false;
  LoopbackServer server(scene, 0);
  auto stub = server.stub();
  grpc::ClientContext context;
  v1::StreamFramesRequest request;
  request.set_velocities(true);
  request.set_contacts(true);
  request.set_stats(true);
  auto reader = stub->StreamFrames(&context, request);  // never read
  for (int i = 0; i < 500 && server.host().status().subscribers == 0; ++i)
    std::this_thread::sleep_for(10ms);
  ASSERT_EQ(server.host().status().subscribers, 1u);
  server.host().step(200);  // warm up allocators and gRPC's buffers
  ASSERT_TRUE(server.host().wait_idle(120s));
  const std::size_t before = heap_in_use();
  server.host().step(2000);
  ASSERT_TRUE(server.host().wait_idle(300s));  // the world was never held up
  EXPECT_EQ(server.host().status().step, 2200u);
  const std::size_t after = heap_in_use();
  const std::size_t grown = after - std::min(before, after);
  EXPECT_LT(grown, 32u << 20) << grown / (1 << 20) << " MB";
  context.TryCancel();
}

}  // namespace
}  // namespace tumble::server
