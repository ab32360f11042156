#pragma once
// Images shared by the renderers and the exporters, rows top to bottom.
// ImageRGBA8: 4 bytes per pixel, sRGB-encoded colour, straight alpha (PNG).
// ImageRGBAF: 4 floats per pixel, linear colour premultiplied by alpha
// (OpenEXR's convention; the path tracer's output).
// ImageChannels: named float channels of one size (a multi-layer EXR's
// channels beside RGBA: the renderers' AOVs).
#include <cstdint>
#include <string>
#include <string_view>
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

// One channel of an ImageChannels: width * height values, rows top to bottom.
struct ImageChannel {
  std::string name;        // e.g. "N.X"
  bool fullFloat = false;  // stored as 32-bit float in a file, else as half
  std::vector<float> pixels;
};

struct ImageChannels {
  int width = 0;
  int height = 0;
  std::vector<ImageChannel> channels;

  // The channel named `name`, or nullptr.
  const ImageChannel* find(std::string_view name) const {
    for (const ImageChannel& c : channels)
      if (c.name == name) return &c;
    return nullptr;
  }
};

}  // namespace crumple
