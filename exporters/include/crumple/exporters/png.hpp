#pragma once
// PNG (8-bit RGBA, sRGB) through libpng. Byte-identical output for identical
// images: fixed compression settings, no timestamp chunk.
#include <cstdint>
#include <string>
#include <vector>

#include "crumple/core/image.hpp"

namespace crumple::exporters {

// Writes atomically: PATH.tmp then rename. Throws InputError if the folder is
// not writable.
void writePng(const std::string& path, const ImageRGBA8& image);
// Throws InputError naming the file for a missing or malformed PNG.
ImageRGBA8 readPng(const std::string& path);
// A PNG file's bytes held in memory (e.g. embedded in a cache); `name` names
// it in errors. Throws InputError for malformed data.
ImageRGBA8 decodePngBytes(const std::vector<std::uint8_t>& bytes, const std::string& name);

}  // namespace crumple::exporters
