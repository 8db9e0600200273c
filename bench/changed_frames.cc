// Frames of a mostly sleeping world: every body in every frame (what each subscriber got before
// changes-only frames) against only the bodies that changed (StreamFramesRequest.changes_only).
// N boxes rest asleep on the ground, one ball falls; per step: the server's frame (its body
// events noted, the frame made, each encoding), the bytes on the wire, and the subscriber's CPU
// (parsing the frame and applying it to its copy of the world). Medians over the steps.
//
//   build/bench/bench_changed_frames [boxes=100000] [steps=60]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <unordered_map>
#include <vector>

#include "convert.h"
#include "frame.h"
#include "hosted_world.h"
#include "timing.h"
#include "tumble/v1/world.pb.h"

namespace tumble::server {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

using tumble::bench::median;

struct Pose {
  double p[3], q[4];
};

// What a subscriber does with a frame: parse it, and set the poses it lists.
double apply(const std::string& bytes, std::unordered_map<std::uint64_t, Pose>& world) {
  const auto start = Clock::now();
  v1::Frame frame;
  if (!frame.ParseFromString(bytes)) std::abort();
  for (int i = 0; i < frame.ids_size(); ++i) {
    Pose& pose = world[frame.ids(i)];
    for (int k = 0; k < 3; ++k)
      pose.p[k] = frame.positions(3 * i + k);
    for (int k = 0; k < 4; ++k)
      pose.q[k] = frame.orientations(4 * i + k);
  }
  return ms_since(start);
}

int run(int boxes, int steps) {
  HostedWorld hosted;
  BodyDef ground;
  ground.shape = HalfSpaceDef{};
  ground.type = BodyType::kStatic;
  std::vector<BodyDef> defs{ground};
  const int side = static_cast<int>(std::ceil(std::sqrt(boxes)));
  for (int i = 0; i < boxes; ++i) {
    BodyDef box;
    box.shape = BoxDef{Vec3(0.5, 0.5, 0.5)};
    box.position = Vec3(1.5 * (i % side), 1.5 * (i / side), 0.5);
    defs.push_back(box);
  }
  if (!hosted.world.create_bodies(defs)) return 1;
  const double dt = 1.0 / 60;
  const auto settle = Clock::now();
  for (int k = 0; k < 600 && hosted.world.last_step().sleeping_bodies < std::uint32_t(boxes); ++k)
    if (!hosted.world.step(dt)) return 1;
  std::printf("%d boxes asleep on the ground after %.1f s of simulated time (%.1f s to settle)\n",
              hosted.world.last_step().sleeping_bodies, hosted.world.time(),
              ms_since(settle) / 1000);
  BodyDef ball;
  ball.shape = SphereDef{0.25};
  ball.position = Vec3(-10, -10, 1000);
  if (!hosted.world.create_body(ball)) return 1;
  hosted.ids.sync(hosted.world);
  std::shared_ptr<const Catalogue> catalogue = updated_catalogue(hosted, nullptr, 0);
  note_changes(hosted);  // the subscribers' first frame lists everything; measured: what follows

  std::vector<double> step_ms, frame_ms, full_encode_ms, changed_encode_ms, full_bytes,
      changed_bytes, full_apply_ms, changed_apply_ms, listed;
  std::unordered_map<std::uint64_t, Pose> full_copy, changed_copy;
  const FrameOptions options;
  std::uint64_t sent_tick = hosted.change_clock;
  for (int k = 0; k < steps; ++k) {
    auto start = Clock::now();
    if (!hosted.world.step(dt)) return 1;
    step_ms.push_back(ms_since(start));
    start = Clock::now();
    note_changes(hosted);
    const std::shared_ptr<const FrameData> frame = make_frame(hosted, dt, catalogue);
    frame_ms.push_back(ms_since(start));
    start = Clock::now();
    v1::Frame full;
    frame_to_proto(*frame, options, &full);
    const std::string full_wire = full.SerializeAsString();
    full_encode_ms.push_back(ms_since(start));
    start = Clock::now();
    v1::Frame changed;
    frame_to_proto(*frame, options, &changed, sent_tick);
    const std::string changed_wire = changed.SerializeAsString();
    changed_encode_ms.push_back(ms_since(start));
    sent_tick = frame->change_clock;
    full_bytes.push_back(static_cast<double>(full_wire.size()));
    changed_bytes.push_back(static_cast<double>(changed_wire.size()));
    listed.push_back(changed.ids_size());
    full_apply_ms.push_back(apply(full_wire, full_copy));
    changed_apply_ms.push_back(apply(changed_wire, changed_copy));
  }
  std::printf("%d steps of the world (%d bodies), medians; the step itself: %.3f ms\n", steps,
              boxes + 2, median(step_ms));
  std::printf("server, per step: body events noted and the frame made %.3f ms\n", median(frame_ms));
  std::printf("%-14s %12s %10s %14s %16s\n", "frames", "bodies/frame", "bytes", "encode (ms)",
              "subscriber (ms)");
  std::printf("%-14s %12d %10.0f %14.3f %16.3f\n", "every body", boxes + 2, median(full_bytes),
              median(full_encode_ms), median(full_apply_ms));
  std::printf("%-14s %12.0f %10.0f %14.3f %16.3f\n", "changes only", median(listed),
              median(changed_bytes), median(changed_encode_ms), median(changed_apply_ms));
  std::printf("ratio          %12s %9.0fx %13.0fx %15.0fx\n", "",
              median(full_bytes) / median(changed_bytes),
              median(full_encode_ms) / median(changed_encode_ms),
              median(full_apply_ms) / median(changed_apply_ms));
  return 0;
}

}  // namespace
}  // namespace tumble::server

int main(int argc, char** argv) {
  const int boxes = argc > 1 ? std::atoi(argv[1]) : 100000;
  const int steps = argc > 2 ? std::atoi(argv[2]) : 60;
  if (boxes < 1 || boxes > 10000000 || steps < 1 || steps > 100000) {
    std::fprintf(stderr, "usage: bench_changed_frames [boxes in 1..1e7] [steps in 1..1e5]\n");
    return 2;
  }
  return tumble::server::run(boxes, steps);
}
