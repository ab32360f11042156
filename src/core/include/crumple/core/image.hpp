#pragma once
// Images shared by the renderers and the exporters, rows top to bottom.
// ImageRGBA8: 4 bytes per pixel, sRGB-encoded colour, straight alpha (PNG).
// ImageRGBAF: 4 floats per pixel, linear colour premultiplied by alpha
// (OpenEXR's convention; the path tracer's output).
#include <cstdint>
#include <vector>

namespace crumple {

struct ImageRGBA8 {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;  // width * height * 4

  ImageRGBA8() = default;
  ImageRGBA8(int w, int h) : width(w), height(h), pixels(static_cast<std::size_t>(w) * h * 4, 0) {}
  std::uint8_t* at(int x, int y) {
    return pixels.data() + (static_cast<std::size_t>(y) * width + x) * 4;
  }
  const std::uint8_t* at(int x, int y) const {
    return pixels.data() + (static_cast<std::size_t>(y) * width + x) * 4;
  }
};

struct ImageRGBAF {
  int width = 0;
  int height = 0;
  std::vector<float> pixels;  // width * height * 4

  ImageRGBAF() = default;
  ImageRGBAF(int w, int h)
      : width(w), height(h), pixels(static_cast<std::size_t>(w) * h * 4, 0.0f) {}
  float* at(int x, int y) { return pixels.data() + (static_cast<std::size_t>(y) * width + x) * 4; }
  const float* at(int x, int y) const {
    return pixels.data() + (static_cast<std::size_t>(y) * width + x) * 4;
  }
};

}  // namespace crumple
