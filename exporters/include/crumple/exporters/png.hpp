#pragma once
// PNG (8-bit RGBA, sRGB) through libpng. Byte-identical output for identical
// images: fixed compression settings, no timestamp chunk.
#include <string>

#include "crumple/core/image.hpp"

namespace crumple::exporters {

// Writes atomically: PATH.tmp then rename. Throws InputError if the folder is
// not writable.
void writePng(const std::string& path, const ImageRGBA8& image);
// Throws InputError naming the file for a missing or malformed PNG.
ImageRGBA8 readPng(const std::string& path);

}  // namespace crumple::exporters
