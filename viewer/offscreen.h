// Off-screen OpenGL through OSMesa (Mesa's software rasteriser): a 3.3 core context rendering into
// memory, on machines without a display.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "gl.h"

struct osmesa_context;  // OSMesaContext's struct, so that GL/osmesa.h stays out of this header

namespace tumble::viewer {

class OffscreenContext {
 public:
  OffscreenContext() = default;
  ~OffscreenContext();
  OffscreenContext(const OffscreenContext&) = delete;
  OffscreenContext& operator=(const OffscreenContext&) = delete;

  // Makes a width x height context current on this thread and loads `gl` from it.
  bool create(int width, int height, std::string* error);
  const Gl& gl() const { return gl_; }
  int width() const { return width_; }
  int height() const { return height_; }
  // The picture after the draws so far: RGBA, rows from the top.
  std::vector<std::uint8_t> read_rgba();

 private:
  ::osmesa_context* context_ = nullptr;
  std::vector<std::uint8_t> buffer_;  // what OSMesa draws into, rows from the bottom
  int width_ = 0, height_ = 0;
  Gl gl_;
};

// Reads a PNG as RGBA pixels, rows from the top (for tests and comparisons).
bool read_png(const std::string& path, std::vector<std::uint8_t>* rgba, int* width, int* height,
              std::string* error);

// Writes RGBA pixels (rows from the top) as a PNG; the message says why not.
bool write_png(const std::string& path, const std::vector<std::uint8_t>& rgba, int width,
               int height, std::string* error);

}  // namespace tumble::viewer
