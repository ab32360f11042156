#pragma once
// Minimal 8-bit RGBA PNG reading and writing with libpng, for the render
// tests only (so they do not depend on the exporters module).
#include <string>

#include "crumple/core/image.hpp"

namespace crumple::render::test {

// Throws std::runtime_error on failure.
void writePng(const std::string& path, const ImageRGBA8& image);
ImageRGBA8 readPng(const std::string& path);

}  // namespace crumple::render::test
