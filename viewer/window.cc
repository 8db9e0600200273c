#include "window.h"

#include <GLFW/glfw3.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <thread>

#include "offscreen.h"
#include "world_view.h"

namespace tumble::viewer {
namespace {

// The camera as a point orbiting its target: distance, azimuth and elevation (radians).
struct Orbit {
  Eigen::Vector3f target;
  float distance, azimuth, elevation;

  explicit Orbit(const Camera& camera) : target(camera.target) {
    const Eigen::Vector3f d = camera.eye - camera.target;
    distance = d.norm();
    azimuth = std::atan2(d.y(), d.x());
    elevation = std::asin(d.z() / distance);
  }
  Camera camera(const Camera& base) const {
    Camera c = base;
    c.target = target;
    c.eye = target + distance * Eigen::Vector3f(std::cos(elevation) * std::cos(azimuth),
                                                std::cos(elevation) * std::sin(azimuth),
                                                std::sin(elevation));
    return c;
  }
};

struct Input {
  Orbit* orbit = nullptr;
  double last_x = 0, last_y = 0;
  bool rotating = false, panning = false;
  int play_toggles = 0, steps = 0, follow_next = 0, contact_toggles = 0, joint_toggles = 0;
  bool stop_following = false;
};

void on_mouse_button(GLFWwindow* window, int button, int action, int) {
  auto* input = static_cast<Input*>(glfwGetWindowUserPointer(window));
  glfwGetCursorPos(window, &input->last_x, &input->last_y);
  if (button == GLFW_MOUSE_BUTTON_LEFT) input->rotating = action == GLFW_PRESS;
  if (button == GLFW_MOUSE_BUTTON_RIGHT) input->panning = action == GLFW_PRESS;
}

void on_cursor(GLFWwindow* window, double x, double y) {
  auto* input = static_cast<Input*>(glfwGetWindowUserPointer(window));
  const auto dx = static_cast<float>(x - input->last_x), dy = static_cast<float>(y - input->last_y);
  input->last_x = x;
  input->last_y = y;
  Orbit& orbit = *input->orbit;
  if (input->rotating) {
    orbit.azimuth -= 0.005f * dx;
    orbit.elevation = std::clamp(orbit.elevation + 0.005f * dy, -1.5f, 1.5f);
  } else if (input->panning) {
    const Eigen::Vector3f right(-std::sin(orbit.azimuth), std::cos(orbit.azimuth), 0);
    const float scale = 0.0015f * orbit.distance;
    orbit.target += scale * (-dx * right + dy * Eigen::Vector3f::UnitZ());
  }
}

void on_scroll(GLFWwindow* window, double, double dy) {
  auto* input = static_cast<Input*>(glfwGetWindowUserPointer(window));
  input->orbit->distance =
      std::clamp(input->orbit->distance * std::pow(0.9f, static_cast<float>(dy)), 0.5f, 500.0f);
}

void on_key(GLFWwindow* window, int key, int, int action, int) {
  if (action != GLFW_PRESS) return;
  auto* input = static_cast<Input*>(glfwGetWindowUserPointer(window));
  if (key == GLFW_KEY_ESCAPE) glfwSetWindowShouldClose(window, GLFW_TRUE);
  if (key == GLFW_KEY_SPACE) ++input->play_toggles;
  if (key == GLFW_KEY_N) ++input->steps;
  if (key == GLFW_KEY_F) ++input->follow_next;
  if (key == GLFW_KEY_C) ++input->contact_toggles;
  if (key == GLFW_KEY_J) ++input->joint_toggles;
  if (key == GLFW_KEY_BACKSPACE) input->stop_following = true;
}

}  // namespace

int run_window(FrameSource& source, const WindowOptions& options) {
  if (!glfwInit()) {
    std::fprintf(stderr, "tumble-viewer: no display for a window (try --offscreen)\n");
    return 1;
  }
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  GLFWwindow* window =
      glfwCreateWindow(options.width, options.height, "tumble-viewer", nullptr, nullptr);
  if (window == nullptr) {
    std::fprintf(stderr, "tumble-viewer: cannot open a 3.3 core window\n");
    glfwTerminate();
    return 1;
  }
  glfwMakeContextCurrent(window);
  glfwSwapInterval(1);
  int code = 0;
  {
    Gl gl;
    std::string error;
    if (!gl.load(glfwGetProcAddress, &error)) {
      std::fprintf(stderr, "tumble-viewer: missing GL functions: %s\n", error.c_str());
      glfwDestroyWindow(window);
      glfwTerminate();
      return 1;
    }
    Renderer renderer(gl);
    if (!renderer.init(&error)) {
      std::fprintf(stderr, "tumble-viewer: %s\n", error.c_str());
      glfwDestroyWindow(window);
      glfwTerminate();
      return 1;
    }
    // Frames arrive on their own thread, every one applied (bodies are described only once);
    // the window draws the newest state at its own pace. A lost server is retried.
    std::mutex mutex;
    WorldView view;
    std::atomic<bool> closing{false}, connected{false}, ended{false};
    std::thread reader([&] {
      while (!closing) {
        source.open();
        {
          std::lock_guard lock(mutex);
          view = WorldView();  // a new stream describes everything again
        }
        v1::Frame frame;
        while (!closing && source.next(&frame)) {
          std::lock_guard lock(mutex);
          view.apply(frame);
          // Under the lock and after the frame: a picture drawn while `connected` shows a world.
          connected = true;
        }
        if (!source.reopens()) {  // a recording played to its end: its last frame stays
          ended = true;
          const Status status = source.finish();
          if (!status) std::fprintf(stderr, "tumble-viewer: %s\n", status.message().c_str());
          return;
        }
        source.finish();
        connected = false;
        if (!closing) std::this_thread::sleep_for(std::chrono::milliseconds(300));
      }
    });

    Orbit orbit(options.camera);
    Input input;
    input.orbit = &orbit;
    glfwSetWindowUserPointer(window, &input);
    glfwSetMouseButtonCallback(window, on_mouse_button);
    glfwSetCursorPosCallback(window, on_cursor);
    glfwSetScrollCallback(window, on_scroll);
    glfwSetKeyCallback(window, on_key);

    const Lighting lighting;
    std::uint64_t following = 0;
    bool running = true, contacts = options.contacts, frame_the_scene = options.frame_the_scene;
    bool joints = options.joints;
    int drawn = 0;
    auto second = std::chrono::steady_clock::now();
    int frames_this_second = 0;
    double fps = 0;
    while (!glfwWindowShouldClose(window)) {
      glfwPollEvents();
      for (; input.play_toggles > 0; --input.play_toggles) {
        v1::ControlRequest request;
        running = !running;
        (running ? request.set_play(true) : request.set_pause(true));
        source.control(request);
      }
      for (; input.steps > 0; --input.steps) {
        v1::ControlRequest request;
        request.set_step(1);
        source.control(request);
        running = false;
      }
      int width = 0, height = 0;
      glfwGetFramebufferSize(window, &width, &height);
      std::vector<std::vector<Instance>> instances, overlay;
      std::uint64_t step = 0;
      double time = 0;
      std::size_t bodies = 0;
      bool showing_world = false;
      {
        std::lock_guard lock(mutex);
        if (input.follow_next > 0) {
          following = view.next_dynamic_body(following);
          input.follow_next = 0;
        }
        if (input.stop_following) following = 0, input.stop_following = false;
        if (following != 0)
          if (const auto at = view.position_of(following)) orbit.target = *at;
        if (input.contact_toggles % 2 == 1) contacts = !contacts;
        input.contact_toggles = 0;
        if (input.joint_toggles % 2 == 1) joints = !joints;
        input.joint_toggles = 0;
        if (frame_the_scene)
          if (const auto around = view.bounds()) {
            const Camera framed_camera =
                framed(orbit.camera(options.camera), around->first, around->second);
            orbit.target = framed_camera.target;
            orbit.distance = (framed_camera.eye - framed_camera.target).norm();
            frame_the_scene = false;
          }
        instances = view.instances(renderer);
        overlay.clear();
        if (contacts) add_overlay(view.contact_overlay(renderer), &overlay);
        if (joints) add_overlay(view.joint_overlay(renderer), &overlay);
        showing_world = connected;
        step = view.step();
        time = view.time();
        bodies = view.body_count();
      }
      renderer.draw(instances, orbit.camera(options.camera), lighting, width, height, overlay);
      // The screenshot counts pictures of the world only: a loaded machine may draw several
      // before the first frame arrives.
      if (showing_world) ++drawn;
      if (!options.screenshot.empty() && drawn >= options.frames) {
        std::vector<std::uint8_t> rgba(static_cast<std::size_t>(width) * height * 4);
        gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
        gl.ReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
        std::vector<std::uint8_t> top_down(rgba.size());
        const std::size_t stride = static_cast<std::size_t>(width) * 4;
        for (int y = 0; y < height; ++y)
          std::copy_n(rgba.data() + (height - 1 - y) * stride, stride,
                      top_down.data() + y * stride);
        if (!write_png(options.screenshot, top_down, width, height, &error)) {
          std::fprintf(stderr, "tumble-viewer: %s\n", error.c_str());
          code = 1;
        }
        glfwSetWindowShouldClose(window, GLFW_TRUE);
      }
      glfwSwapBuffers(window);
      ++frames_this_second;
      const auto now = std::chrono::steady_clock::now();
      if (now - second >= std::chrono::seconds(1)) {
        fps = frames_this_second / std::chrono::duration<double>(now - second).count();
        frames_this_second = 0;
        second = now;
        char title[160];
        std::snprintf(title, sizeof title,
                      "tumble-viewer - step %llu, t = %.2f s, %zu bodies, %.0f fps%s",
                      static_cast<unsigned long long>(step), time, bodies, fps,
                      ended       ? " - end of the recording"
                      : connected ? ""
                                  : " - server lost, reconnecting");
        glfwSetWindowTitle(window, title);
      }
    }
    {
      std::lock_guard lock(mutex);
      closing = true;
      source.cancel();
    }
    reader.join();
  }
  glfwDestroyWindow(window);
  glfwTerminate();
  return code;
}

}  // namespace tumble::viewer
