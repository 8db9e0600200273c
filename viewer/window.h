// The window front end (GLFW): draws the frames as they come (a server's or a recording's), with
// orbit (left drag), pan (right drag) and zoom (wheel); Space plays or pauses the server, N steps
// it once, C shows or hides contacts, J joints, F follows the next body (again: the one after;
// Backspace: stop following), Esc closes. Step, simulated time, bodies and frame rate show in the
// title.
#pragma once

#include <string>

#include "frame_source.h"
#include "renderer.h"

namespace tumble::viewer {

struct WindowOptions {
  int width = 1280, height = 720;
  Camera camera;
  // With a path: save the picture after `frames` drawn frames and close (for tests).
  std::string screenshot;
  int frames = 0;
  bool contacts = false;  // the overlays at start
  bool joints = false;
  // Frame the bodies of the first frame (the camera's direction kept); false keeps the camera.
  bool frame_the_scene = false;
};

// Runs until the window is closed; the exit code.
int run_window(FrameSource& source, const WindowOptions& options);

}  // namespace tumble::viewer
