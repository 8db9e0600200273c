// tumble-viewer: attaches to a running tumble-server and draws its world, or plays a recording,
// in a window (GLFW) or off screen (OSMesa) into PNG frames; if the server goes away it keeps the
// last picture, says so, and reconnects.
//   tumble-viewer --server 127.0.0.1:50051
//   tumble-viewer --server 127.0.0.1:50051 --offscreen --out frames --frames 120 --every 2
//   tumble-viewer --replay run.rec
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <thread>

#include "client.h"
#include "frame_source.h"
#include "offscreen.h"
#include "tumble/command_line.h"
#include "window.h"
#include "world_view.h"

using namespace tumble;
using tumble::wire::Result;
using tumble::wire::Status;

int main(int argc, char** argv) {
  CLI::App app{"tumble-viewer: draws a running tumble-server's world, or plays a recording."};
  cli::keep_conventions(app, "tumble-viewer");
  client::Connection connection;
  std::string out_dir = "frames", size = "1280x720";
  std::uint32_t frames = 60, every = 1;
  double give_up_after = 30;
  std::vector<float> eye{8, -12, 6}, target{0, 0, 1};
  bool offscreen = false;
  app.add_option("--server", connection.address, "the server's address")->envname("TUMBLE_SERVER");
  app.add_option("--token", connection.token, "bearer token")->envname("TUMBLE_TOKEN");
  app.add_option("--tls-ca", connection.tls_ca_file, "TLS: the certificate authority (PEM)")
      ->envname("TUMBLE_TLS_CA");
  std::string screenshot, replay;
  app.add_option("--replay", replay,
                 "play this recording (tumble record, tumble-server --record) instead of a "
                 "server's world: in a window at its recorded pace, off screen as fast as drawn")
      ->check(cli::existing_file);
  bool contacts = false;
  app.add_flag("--contacts", contacts, "draw contact points and normals");
  bool joints = false;
  app.add_flag("--joints", joints, "draw joints: each anchor and axis");
  app.add_flag("--offscreen", offscreen, "render with OSMesa into PNG files (no display needed)");
  app.add_option(
      "--screenshot", screenshot,
      "window: save the picture after --frames pictures of the world into this PNG and close");
  app.add_option("--out", out_dir, "folder for the PNG frames");
  app.add_option("--frames", frames, "how many pictures to write")->check(cli::positive);
  app.add_option("--every", every, "draw every Nth frame received")->check(cli::positive);
  double fps = 0;
  std::string video;
  app.add_option("--fps", fps,
                 "pictures per simulated second (instead of --every), and the video's frame rate")
      ->check(cli::non_negative);
  app.add_option("--video", video, "also encode the pictures into this video (needs ffmpeg)");
  app.add_option("--size", size, "WIDTHxHEIGHT");
  app.add_option("--eye", eye,
                 "camera position x,y,z (m; default: framing the bodies from 8,-12,6)")
      ->delimiter(',')
      ->expected(3);
  app.add_option("--target", target, "point looked at x,y,z (m; default: the bodies' centre)")
      ->delimiter(',')
      ->expected(3);
  app.add_option("--give-up-after", give_up_after,
                 "seconds without a server before stopping (it reconnects meanwhile)");
  if (const int exit_status = cli::parse(app, argc, argv); exit_status >= 0) return exit_status;

  int width = 0, height = 0;
  if (std::sscanf(size.c_str(), "%dx%d", &width, &height) != 2 || width <= 0 || height <= 0) {
    std::fprintf(stderr, "tumble-viewer: --size: expected WIDTHxHEIGHT, got %s\n", size.c_str());
    return 2;
  }
  std::optional<client::Client> connected;
  std::unique_ptr<viewer::FrameSource> source;
  if (!replay.empty()) {
    auto opened = viewer::RecordingSource::open_file(replay, /*paced=*/!offscreen);
    if (!opened) {
      std::fprintf(stderr, "tumble-viewer: --replay: %s\n", opened.error().c_str());
      return 2;
    }
    source = std::move(opened).value();
  } else {
    Result<client::Client> made = client::Client::connect(connection);
    if (!made) {
      std::fprintf(stderr, "tumble-viewer: %s\n", made.error().c_str());
      return 2;
    }
    connected.emplace(std::move(made).value());
    // Contacts and joints are cheap to carry in a window, which toggles them; pictures ask only
    // if drawn.
    source = std::make_unique<viewer::ServerSource>(*connected, contacts || !offscreen,
                                                    joints || !offscreen);
  }
  viewer::Camera camera;
  camera.eye = {eye[0], eye[1], eye[2]};
  camera.target = {target[0], target[1], target[2]};
  // Without --eye or --target, the camera frames the bodies it first sees, from the default
  // direction.
  bool frame_the_scene = app.count("--eye") == 0 && app.count("--target") == 0;
  if (!offscreen) {
    viewer::WindowOptions options;
    options.width = width;
    options.height = height;
    options.camera = camera;
    options.screenshot = screenshot;
    options.frames = static_cast<int>(frames);
    options.contacts = contacts;
    options.joints = joints;
    options.frame_the_scene = frame_the_scene;
    return viewer::run_window(*source, options);
  }

  std::error_code made;
  std::filesystem::create_directories(out_dir, made);
  if (made) {
    std::fprintf(stderr, "tumble-viewer: --out: %s: %s\n", out_dir.c_str(), made.message().c_str());
    return 2;
  }
  viewer::OffscreenContext context;
  std::string error;
  if (!context.create(width, height, &error)) {
    std::fprintf(stderr, "tumble-viewer: %s\n", error.c_str());
    return 1;
  }
  viewer::Renderer renderer(context.gl());
  if (!renderer.init(&error)) {
    std::fprintf(stderr, "tumble-viewer: %s\n", error.c_str());
    return 1;
  }
  const viewer::Lighting lighting;
  // The video: raw frames piped to ffmpeg, which encodes them as they come.
  FILE* encoder = nullptr;
  if (!video.empty()) {
    if (std::system("command -v ffmpeg >/dev/null 2>&1") != 0) {
      std::fprintf(stderr, "tumble-viewer: --video: ffmpeg is not installed\n");
      return 2;
    }
    const std::string command = "ffmpeg -loglevel error -y -f rawvideo -pix_fmt rgba -s " +
                                std::to_string(width) + "x" + std::to_string(height) + " -r " +
                                std::to_string(fps > 0 ? fps : 30) + " -i - -pix_fmt yuv420p '" +
                                video + "'";
    encoder = popen(command.c_str(), "w");
    if (encoder == nullptr) {
      std::fprintf(stderr, "tumble-viewer: --video: cannot start ffmpeg\n");
      return 1;
    }
  }

  std::uint32_t written = 0;
  double next_picture_time = -1;  // with --fps: simulated time of the next picture
  std::uint64_t received = 0;
  auto lost_since = std::chrono::steady_clock::now();
  while (written < frames) {
    // A new stream describes every body again; the view starts over with it.
    viewer::WorldView view;
    source->open();
    v1::Frame frame;
    bool any = false;
    while (written < frames && source->next(&frame)) {
      any = true;
      view.apply(frame);
      if (fps > 0) {
        if (frame.time() < next_picture_time) continue;
        next_picture_time = std::max(next_picture_time, frame.time()) + 1 / fps;
      } else if (received++ % every != 0) {
        continue;
      }
      if (frame_the_scene) {  // once, on the first picture with bodies
        if (const auto around = view.bounds()) {
          camera = viewer::framed(camera, around->first, around->second);
          frame_the_scene = false;
        }
      }
      std::vector<std::vector<viewer::Instance>> overlay;
      if (contacts) viewer::add_overlay(view.contact_overlay(renderer), &overlay);
      if (joints) viewer::add_overlay(view.joint_overlay(renderer), &overlay);
      renderer.draw(view.instances(renderer), camera, lighting, width, height, overlay);
      const std::vector<std::uint8_t> picture = context.read_rgba();
      char name[64];
      std::snprintf(name, sizeof name, "frame-%05u.png", written);
      const std::string path = (std::filesystem::path(out_dir) / name).string();
      if (!viewer::write_png(path, picture, width, height, &error)) {
        std::fprintf(stderr, "tumble-viewer: %s\n", error.c_str());
        return 1;
      }
      if (encoder != nullptr) std::fwrite(picture.data(), 1, picture.size(), encoder);
      ++written;
    }
    if (written >= frames) break;
    const Status ended = source->finish();
    if (!source->reopens()) {  // the recording ended before --frames pictures
      if (!ended) {
        std::fprintf(stderr, "tumble-viewer: --replay: %s\n", ended.message().c_str());
        return 1;
      }
      break;
    }
    if (any) {
      lost_since = std::chrono::steady_clock::now();
      std::fprintf(stderr,
                   "tumble-viewer: lost the server (%s); keeping the last picture, "
                   "reconnecting\n",
                   ended ? "stream ended" : ended.message().c_str());
    }
    if (std::chrono::steady_clock::now() - lost_since >
        std::chrono::duration<double>(give_up_after)) {
      std::fprintf(stderr, "tumble-viewer: no server at %s for %.0f s; %u pictures written\n",
                   connection.address.c_str(), give_up_after, written);
      return 1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  std::printf("tumble-viewer: %u pictures (%dx%d) in %s\n", written, width, height,
              out_dir.c_str());
  if (encoder != nullptr) {
    if (pclose(encoder) != 0) {
      std::fprintf(stderr, "tumble-viewer: --video: ffmpeg failed\n");
      return 1;
    }
    std::printf("tumble-viewer: video %s\n", video.c_str());
  }
  return 0;
}
