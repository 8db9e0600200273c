#include "offscreen.h"

#include <GL/osmesa.h>
#include <png.h>

#include <algorithm>
#include <cstdio>

namespace tumble::viewer {

OffscreenContext::~OffscreenContext() {
  if (context_ != nullptr) OSMesaDestroyContext(context_);
}

bool OffscreenContext::create(int width, int height, std::string* error) {
  if (width <= 0 || height <= 0 || width > 16384 || height > 16384) {
    *error = "size: must be between 1x1 and 16384x16384";
    return false;
  }
  const int attributes[] = {OSMESA_FORMAT,
                            OSMESA_RGBA,
                            OSMESA_DEPTH_BITS,
                            24,
                            OSMESA_PROFILE,
                            OSMESA_CORE_PROFILE,
                            OSMESA_CONTEXT_MAJOR_VERSION,
                            3,
                            OSMESA_CONTEXT_MINOR_VERSION,
                            3,
                            0};
  context_ = OSMesaCreateContextAttribs(attributes, nullptr);
  if (context_ == nullptr) {
    *error = "OSMesa: cannot create a 3.3 core context";
    return false;
  }
  width_ = width;
  height_ = height;
  buffer_.assign(static_cast<std::size_t>(width) * height * 4, 0);
  if (!OSMesaMakeCurrent(context_, buffer_.data(), GL_UNSIGNED_BYTE, width, height)) {
    *error = "OSMesa: cannot make the context current";
    return false;
  }
  std::string missing;
  if (!gl_.load(OSMesaGetProcAddress, &missing)) {
    *error = "OSMesa: missing GL functions: " + missing;
    return false;
  }
  return true;
}

std::vector<std::uint8_t> OffscreenContext::read_rgba() {
  gl_.Finish();
  std::vector<std::uint8_t> rows(buffer_.size());
  const std::size_t stride = static_cast<std::size_t>(width_) * 4;
  for (int y = 0; y < height_; ++y)
    std::copy_n(buffer_.data() + (height_ - 1 - y) * stride, stride, rows.data() + y * stride);
  return rows;
}

bool write_png(const std::string& path, const std::vector<std::uint8_t>& rgba, int width,
               int height, std::string* error) {
  FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) {
    *error = path + ": cannot create";
    return false;
  }
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
  if (png == nullptr || info == nullptr || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    std::fclose(file);
    *error = path + ": cannot write PNG";
    return false;
  }
  png_init_io(png, file);
  // Level 1: a frame a few times faster to write for a slightly larger file.
  png_set_compression_level(png, 1);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8,
               PNG_COLOR_TYPE_RGBA, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < height; ++y)
    png_write_row(png, rgba.data() + static_cast<std::size_t>(y) * width * 4);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return std::fclose(file) == 0;
}

bool read_png(const std::string& path, std::vector<std::uint8_t>* rgba, int* width, int* height,
              std::string* error) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&image, path.c_str())) {
    *error = path + ": " + image.message;
    return false;
  }
  image.format = PNG_FORMAT_RGBA;
  rgba->resize(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, rgba->data(), 0, nullptr)) {
    *error = path + ": " + image.message;
    png_image_free(&image);
    return false;
  }
  *width = static_cast<int>(image.width);
  *height = static_cast<int>(image.height);
  return true;
}

}  // namespace tumble::viewer
