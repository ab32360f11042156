#pragma once
// Helpers shared by the render tests (test_render only: they use the
// CRUMPLE_RENDER_* directories it defines).
//
// Golden images: an exact byte comparison (llvmpipe is pinned to SSE4.1, so
// renders are byte-identical across runs and machines with the same
// Mesa/LLVM). CRUMPLE_BLESS=1 rewrites the golden file instead and reports
// the test as SKIPPED; a mismatch writes NAME.actual.png into the build
// directory. CRUMPLE_RENDER_DUMP=1 writes every rendered image there.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "crumple/core/image.hpp"
#include "crumple/render/view.hpp"
#include "png_io.hpp"

namespace crumple::render::test {

inline bool envFlag(const char* name) {
  const char* v = std::getenv(name);
  return v != nullptr && *v != '\0' && std::string(v) != "0";
}

inline void maybeDump(const std::string& name, const ImageRGBA8& img) {
  if (envFlag("CRUMPLE_RENDER_DUMP"))
    writePng(std::string(CRUMPLE_RENDER_OUT_DIR) + "/" + name + ".png", img);
}

// The pixel whose area contains the projection of a world point.
inline const std::uint8_t* pixelAt(const ImageRGBA8& img, const Camera& cam, const Vec3& world) {
  const auto p = projectToPixel(cam, world);
  EXPECT_TRUE(p.has_value());
  const int x = std::clamp(static_cast<int>(std::floor(p->x())), 0, img.width - 1);
  const int y = std::clamp(static_cast<int>(std::floor(p->y())), 0, img.height - 1);
  return img.at(x, y);
}

inline std::vector<std::uint8_t> readBytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(f), {});
}

// Compares `img` byte for byte with golden/NAME.png (or rewrites it under
// CRUMPLE_BLESS=1). Call it last in a test: blessing skips the test.
inline void expectMatchesGolden(const std::string& name, const ImageRGBA8& img) {
  const std::string golden = std::string(CRUMPLE_RENDER_GOLDEN_DIR) + "/" + name + ".png";
  if (envFlag("CRUMPLE_BLESS")) {
    writePng(golden, img);
    GTEST_SKIP() << "CRUMPLE_BLESS: rewrote " << golden;
  }
  ASSERT_TRUE(std::filesystem::exists(golden))
      << golden << " is missing; run with CRUMPLE_BLESS=1 to create it";
  const ImageRGBA8 ref = readPng(golden);
  ASSERT_EQ(ref.width, img.width);
  ASSERT_EQ(ref.height, img.height);
  if (ref.pixels != img.pixels) {
    int differing = 0, maxDiff = 0;
    for (std::size_t i = 0; i < img.pixels.size(); ++i) {
      const int d = std::abs(int(img.pixels[i]) - int(ref.pixels[i]));
      differing += d != 0;
      maxDiff = std::max(maxDiff, d);
    }
    const std::string actual = std::string(CRUMPLE_RENDER_OUT_DIR) + "/" + name + ".actual.png";
    writePng(actual, img);
    FAIL() << differing << " bytes differ from " << golden << " (max difference " << maxDiff
           << "); the render is in " << actual
           << ". If the change is intended, re-bless with CRUMPLE_BLESS=1.";
  }
}

}  // namespace crumple::render::test
