#pragma once
// What every image writer checks first. Internal to the exporters.
#include <stdexcept>
#include <string>

namespace crumple::exporters {

// std::invalid_argument naming the path and the format unless the image has
// a positive size and four channels a pixel (`unit`: what a channel is).
template <typename Image>
void checkImageToWrite(const std::string& path, const char* format, const Image& image,
                       const char* unit) {
  if (image.width <= 0 || image.height <= 0 ||
      image.pixels.size() != static_cast<std::size_t>(image.width) * image.height * 4)
    throw std::invalid_argument(path + ": cannot write " + format + ": invalid image (" +
                                std::to_string(image.width) + "x" + std::to_string(image.height) +
                                ", " + std::to_string(image.pixels.size()) + " " + unit + ")");
}

}  // namespace crumple::exporters
