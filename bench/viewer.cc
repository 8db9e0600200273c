// The off-screen renderer (OSMesa, Mesa's llvmpipe): frames per second at 1280x720 drawing 1,000
// and 10,000 boxes (a lattice, each turned), and what reading the picture back and writing it as
// PNG add. Usage: bench_viewer [frames per row, default 30]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "offscreen.h"
#include "renderer.h"
#include "timing.h"

namespace {

using namespace tumble::viewer;
using Clock = std::chrono::steady_clock;

using tumble::bench::median;

}  // namespace

int main(int argc, char** argv) {
  const int frames = argc > 1 ? std::atoi(argv[1]) : 30;
  constexpr int kWidth = 1280, kHeight = 720;
  OffscreenContext context;
  std::string error;
  if (!context.create(kWidth, kHeight, &error)) {
    std::fprintf(stderr, "bench_viewer: %s\n", error.c_str());
    return 1;
  }
  Renderer renderer(context.gl());
  if (!renderer.init(&error)) {
    std::fprintf(stderr, "bench_viewer: %s\n", error.c_str());
    return 1;
  }
  std::printf("bench_viewer: %s, %dx%d, median of %d frames\n",
              reinterpret_cast<const char*>(context.gl().GetString(GL_RENDERER)), kWidth, kHeight,
              frames);
  std::printf(
      "| boxes | draw ms | frames/s | read back ms | PNG write ms |\n|---|---|---|---|---|\n");
  for (int count : {1000, 10000}) {
    std::vector<std::vector<Instance>> instances(3);
    const int side = static_cast<int>(std::ceil(std::cbrt(count)));
    Instance ground;
    ground.model.topLeftCorner<3, 3>() *= 200;
    ground.material.x() = 1;
    instances[renderer.ground_mesh()].push_back(ground);
    for (int i = 0; i < count; ++i) {
      Instance box;
      const Eigen::Vector3f at(1.5f * (i % side) - side * 0.75f,
                               1.5f * ((i / side) % side) - side * 0.75f,
                               0.5f + 1.5f * (i / (side * side)));
      const Eigen::Quaternionf turn(
          Eigen::AngleAxisf(0.1f * i, Eigen::Vector3f(1, 2, 3).normalized()));
      box.model = (Eigen::Translation3f(at) * turn * Eigen::Scaling(0.5f)).matrix();
      box.colour = {0.3f + 0.5f * (i % 3) / 2, 0.4f, 0.8f - 0.5f * (i % 5) / 4, 1};
      instances[renderer.box_mesh()].push_back(box);
    }
    Camera camera;
    camera.eye = Eigen::Vector3f(1.2f, -1.8f, 1.0f) * side * 1.5f;
    camera.target = {0, 0, side * 0.5f};
    const Lighting lighting;
    std::vector<double> draw, read, write;
    for (int f = 0; f < frames + 2; ++f) {
      auto start = Clock::now();
      renderer.draw(instances, camera, lighting, kWidth, kHeight);
      context.gl().Finish();
      const double drawn = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
      start = Clock::now();
      const std::vector<std::uint8_t> rgba = context.read_rgba();
      const double got = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
      start = Clock::now();
      write_png("/tmp/bench_viewer.png", rgba, kWidth, kHeight, &error);
      const double written =
          std::chrono::duration<double, std::milli>(Clock::now() - start).count();
      if (f < 2) continue;  // warm-up
      draw.push_back(drawn);
      read.push_back(got);
      write.push_back(written);
    }
    std::printf("| %d | %.1f | %.0f | %.2f | %.1f |\n", count, median(draw), 1000 / median(draw),
                median(read), median(write));
  }
  std::remove("/tmp/bench_viewer.png");
  return 0;
}
