#pragma once
// What the image writers share: the check of the image, and the end of an
// atomic write (PATH.tmp, then renamed). Internal to the exporters.
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>

#include "crumple/core/error.hpp"

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

// Closes `file`, written as `tmp`, and renames it to `path` when `problem`
// (what went wrong so far) is empty; else, or when either fails, removes tmp
// and throws InputError "cannot write <format>: <problem>".
inline void finishAtomicWrite(std::FILE* file, const std::string& tmp, const std::string& path,
                              const char* format, std::string problem) {
  if (std::fclose(file) != 0 && problem.empty()) problem = std::strerror(errno);
  if (problem.empty() && std::rename(tmp.c_str(), path.c_str()) != 0)
    problem = std::string("cannot rename the temporary file: ") + std::strerror(errno);
  if (!problem.empty()) {
    std::remove(tmp.c_str());
    throw InputError(path, std::string("cannot write ") + format + ": " + problem);
  }
}

}  // namespace crumple::exporters
