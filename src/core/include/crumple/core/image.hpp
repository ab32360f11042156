#pragma once
// An 8-bit RGBA image, rows top to bottom, 4 bytes per pixel (straight alpha,
// sRGB-encoded colour). Shared by the renderers and the PNG exporter.
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

}  // namespace crumple
