// tumble-viewer attached to a tumble-server, both as processes: pictures of different steps
// differ where the bodies fell and agree where nothing moved, the viewer outlives a restart of
// the server, and its window (under Xvfb) draws what its off-screen renderer draws.
#include <gtest/gtest.h>

#include <thread>

#include "offscreen.h"
#include "process_support.h"

namespace tumble::viewer {
namespace {

using namespace tumble::testing;

struct Png {
  std::vector<std::uint8_t> rgba;
  int width = 0, height = 0;
};

Png load(const std::string& path) {
  Png png;
  std::string error;
  EXPECT_TRUE(read_png(path, &png.rgba, &png.width, &png.height, &error)) << error;
  return png;
}

std::string viewer(const Server& server, const std::string& out, int frames) {
  // A fixed camera (without --eye and --target the viewer frames what it first sees), so that
  // pictures of different steps compare.
  return std::string(TUMBLE_VIEWER_BINARY) + " --server " + server.address +
         " --offscreen --eye 8,-12,6 --target 0,0,1 --size 320x180 --give-up-after 20 --out " +
         out + " --frames " + std::to_string(frames);
}

TEST(ViewerProcess, PicturesOfLaterStepsDifferWhereTheBodiesFell) {
  Server server;
  ASSERT_NO_FATAL_FAILURE(server.start({"--paused"}));
  TempDir dir;
  const Output first = run(viewer(server, dir / "start", 1));
  ASSERT_EQ(first.code, 0) << first.text;
  const Output stepped =
      run(std::string(TUMBLE_CLI_BINARY) + " --server " + server.address + " step 90");
  ASSERT_EQ(stepped.code, 0) << stepped.text;
  const Output later = run(viewer(server, dir / "later", 1));
  ASSERT_EQ(later.code, 0) << later.text;
  const Png a = load(dir / "start/frame-00000.png"), b = load(dir / "later/frame-00000.png");
  ASSERT_EQ(a.width, 320);
  ASSERT_EQ(a.rgba.size(), b.rgba.size());
  // The default scene's boxes start 1.5-8 m up, in the middle of the picture, and land on the
  // floor (some scatter towards the camera): the middle changes, the sky in the top corners
  // does not.
  int changed = 0, changed_in_corners = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      const std::size_t i = (static_cast<std::size_t>(y) * a.width + x) * 4;
      const bool differs = std::abs(a.rgba[i] - b.rgba[i]) +
                               std::abs(a.rgba[i + 1] - b.rgba[i + 1]) +
                               std::abs(a.rgba[i + 2] - b.rgba[i + 2]) >
                           30;
      changed += differs;
      const bool corner = y < a.height / 5 && (x < a.width / 5 || x >= a.width * 4 / 5);
      if (corner) changed_in_corners += differs;
    }
  EXPECT_GT(changed, a.width * a.height / 50) << changed;
  EXPECT_EQ(changed_in_corners, 0);
}

TEST(ViewerProcess, SurvivesTheServerStoppingAndStartingAgain) {
  // The first server is paused: it sends the viewer its one picture and no more, so the viewer is
  // still waiting when it stops (a running one could stream all 400 before the stop on a busy
  // machine, and the viewer would end without losing it). The second runs flat out.
  Server server;
  ASSERT_NO_FATAL_FAILURE(server.start({"--paused"}));
  TempDir dir;
  FILE* viewing = popen((viewer(server, dir / "frames", 400) + " 2>&1").c_str(), "r");
  ASSERT_NE(viewing, nullptr);
  for (int i = 0; i < 500 && !std::filesystem::exists(dir / "frames/frame-00000.png"); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_TRUE(std::filesystem::exists(dir / "frames/frame-00000.png"));
  int code = -1;
  std::string last;
  const std::string address = server.address;
  server.stop(&code, &last);
  Server again;
  ASSERT_NO_FATAL_FAILURE(again.start({}, address));
  std::string output;
  char buffer[512];
  while (fgets(buffer, sizeof buffer, viewing) != nullptr)
    output += buffer;
  EXPECT_EQ(pclose(viewing), 0) << output;
  EXPECT_NE(output.find("lost the server"), std::string::npos) << output;
  EXPECT_NE(output.find("400 pictures"), std::string::npos) << output;
  EXPECT_TRUE(std::filesystem::exists(dir / "frames/frame-00399.png"));
}

// The window under Xvfb and the off-screen renderer draw the same state alike.
// tumble-server --record keeps every frame (a subscriber over the network drops the ones it is
// too slow for); tumble replay reads them all, and the viewer plays the file without a server,
// off screen and in a window.
TEST(ViewerProcess, TheServersRecordingHasEveryStepAndTheViewerPlaysIt) {
  TempDir dir;
  Server server;
  ASSERT_NO_FATAL_FAILURE(server.start({"--record", dir / "run.rec", "--paused"}));
  const Output stepped =
      run(std::string(TUMBLE_CLI_BINARY) + " --server " + server.address + " step 200");
  ASSERT_EQ(stepped.code, 0) << stepped.text;
  int code = -1;
  std::string last;
  server.stop(&code, &last);
  ASSERT_EQ(code, 0);
  const Output replay = run(std::string(TUMBLE_CLI_BINARY) + " replay " + dir / "run.rec");
  ASSERT_EQ(replay.code, 0) << replay.text.substr(0, 400);
  // Every step from the state before the first (step 0) to 200, in order, none dropped (a
  // command's change, such as the step request's settings, adds a frame of the same step).
  std::size_t next_step = 0, with_contacts = 0, frames = 0;
  std::size_t line_start = 0;
  while (line_start < replay.text.size()) {
    const std::size_t end = replay.text.find('\n', line_start);
    const std::string line = replay.text.substr(line_start, end - line_start);
    const std::size_t step = std::stoul(line.substr(line.find("\"step\":") + 7));
    EXPECT_TRUE(step == next_step || step + 1 == next_step) << step << " after " << next_step;
    next_step = step + 1;
    EXPECT_NE(line.find("\"dropped\":0"), std::string::npos) << "frame " << frames;
    with_contacts += line.find("\"contacts\":[{") != std::string::npos;
    ++frames;
    line_start = end + 1;
  }
  EXPECT_EQ(next_step, 201u);
  EXPECT_GT(with_contacts, frames / 2);

  const Output pictures =
      run(std::string(TUMBLE_VIEWER_BINARY) + " --replay " + dir / "run.rec" +
          " --offscreen --size 320x180 --frames 2 --every 20 --out " + dir / "replayed");
  ASSERT_EQ(pictures.code, 0) << pictures.text;
  const Png first = load(dir / "replayed/frame-00000.png");
  EXPECT_EQ(first.width, 320);
  const Output window =
      run("ASAN_OPTIONS=detect_leaks=0 timeout 60 xvfb-run -a -s '-screen 0 1280x720x24' " +
          std::string(TUMBLE_VIEWER_BINARY) + " --replay " + dir / "run.rec" +
          " --size 320x180 --frames 3 --screenshot " + dir / "window.png");
  ASSERT_EQ(window.code, 0) << window.text;
  EXPECT_EQ(load(dir / "window.png").width, 320);
  // A file that is not a recording is refused by name.
  const Output refused = run(std::string(TUMBLE_VIEWER_BINARY) + " --replay " +
                             std::string(TUMBLE_VIEWER_BINARY) + " --offscreen");
  EXPECT_EQ(refused.code, 2);
  EXPECT_NE(refused.text.find("not a tumble recording"), std::string::npos) << refused.text;
}

TEST(ViewerProcess, TheWindowAndTheOffscreenPictureAgree) {
  Server server;
  ASSERT_NO_FATAL_FAILURE(server.start({"--paused"}));
  TempDir dir;
  // Under AddressSanitizer, leak checks are off for the window process alone: the X and GL
  // driver libraries GLFW loads are unloaded before the check, so what they keep cannot even be
  // attributed (the variable does nothing in other builds).
  const Output window =
      run("ASAN_OPTIONS=detect_leaks=0 timeout 60 xvfb-run -a -s "
          "'-screen 0 1280x720x24' " +
          std::string(TUMBLE_VIEWER_BINARY) + " --server " + server.address +
          " --eye 8,-12,6 --target 0,0,1 --size 320x180 --frames 3 --screenshot " + dir / "window.png");
  ASSERT_EQ(window.code, 0) << window.text;
  const Output offscreen = run(viewer(server, dir / "offscreen", 1));
  ASSERT_EQ(offscreen.code, 0) << offscreen.text;
  const Png a = load(dir / "window.png"), b = load(dir / "offscreen/frame-00000.png");
  ASSERT_EQ(a.width, b.width);
  ASSERT_EQ(a.height, b.height);
  int differing = 0, bodies = 0;
  for (std::size_t i = 0; i < a.rgba.size(); i += 4) {
    int difference = 0;
    for (int k = 0; k < 3; ++k)
      difference = std::max(difference, std::abs(a.rgba[i + k] - b.rgba[i + k]));
    differing += difference > 8;
    bodies += a.rgba[i] > a.rgba[i + 2] + 40;  // orange, red, yellow boxes: warm pixels
  }
  EXPECT_LT(differing, a.width * a.height / 100) << differing;
  EXPECT_GT(bodies, a.width * a.height / 100);  // and the picture is not just floor and sky
}

}  // namespace
}  // namespace tumble::viewer
