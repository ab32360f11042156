#include "png_io.hpp"

#include <png.h>

#include <cstring>
#include <stdexcept>

namespace crumple::render::test {

void writePng(const std::string& path, const ImageRGBA8& image) {
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width);
  png.height = static_cast<png_uint_32>(image.height);
  png.format = PNG_FORMAT_RGBA;
  if (!png_image_write_to_file(&png, path.c_str(), 0, image.pixels.data(), 0, nullptr))
    throw std::runtime_error("writePng " + path + ": " + png.message);
}

ImageRGBA8 readPng(const std::string& path) {
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, path.c_str()))
    throw std::runtime_error("readPng " + path + ": " + png.message);
  png.format = PNG_FORMAT_RGBA;
  ImageRGBA8 image(static_cast<int>(png.width), static_cast<int>(png.height));
  if (!png_image_finish_read(&png, nullptr, image.pixels.data(), 0, nullptr)) {
    png_image_free(&png);
    throw std::runtime_error("readPng " + path + ": " + png.message);
  }
  return image;
}

}  // namespace crumple::render::test
