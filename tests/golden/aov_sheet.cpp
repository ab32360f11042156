// A contact sheet of a frame's AOV layers, for docs/RENDERING.md "AOVs"
// (scripts/aov-contact-sheet.sh): cell 1 the beauty, 2 region.RGB (flat red,
// curved green, singular neighbourhoods blue), 3 N.XYZ as 0.5 + 0.5 n, 4 Z
// (near white to far black over the hit pixels), 5 IndexOB.X (sheet white,
// ground grey, props by id), 6 IndexHandle.X (one hue per handle).
//
//   aov_sheet FRAME.exr OUT.png [CELL_WIDTH]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "crumple/exporters/exr.hpp"
#include "crumple/exporters/png.hpp"
#include "crumple/render/contact_sheet.hpp"
#include "crumple/render/renderer.hpp"

namespace {

using crumple::ImageChannels;
using crumple::ImageRGBA8;

const std::vector<float>& channel(const ImageChannels& image, const std::string& name) {
  const crumple::ImageChannel* c = image.find(name);
  if (!c) throw std::runtime_error("the EXR has no channel " + name);
  return c->pixels;
}

// An opaque 8-bit image from a per-pixel colour in [0, 1] (encoded as sRGB).
template <class Colour>
ImageRGBA8 paint(const ImageChannels& image, Colour colour) {
  ImageRGBA8 out(image.width, image.height);
  for (std::size_t i = 0; i < static_cast<std::size_t>(image.width) * image.height; ++i) {
    const crumple::Vec3 c = colour(i);
    for (int k = 0; k < 3; ++k)
      out.pixels[4 * i + static_cast<std::size_t>(k)] =
          crumple::render::linearToSrgb8(std::clamp(c(k), 0.0, 1.0));
    out.pixels[4 * i + 3] = 255;
  }
  return out;
}

// A distinct colour per small integer id (0: black).
crumple::Vec3 idColour(float id) {
  if (id <= 0.0f) return crumple::Vec3::Zero();
  const double h = std::fmod(0.618034 * id, 1.0) * 6.0;
  const double x = 1.0 - std::abs(std::fmod(h, 2.0) - 1.0);
  const int s = static_cast<int>(h);
  const crumple::Vec3 rgb = s == 0   ? crumple::Vec3(1, x, 0)
                            : s == 1 ? crumple::Vec3(x, 1, 0)
                            : s == 2 ? crumple::Vec3(0, 1, x)
                            : s == 3 ? crumple::Vec3(0, x, 1)
                            : s == 4 ? crumple::Vec3(x, 0, 1)
                                     : crumple::Vec3(1, 0, x);
  return 0.6 * rgb;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: aov_sheet FRAME.exr OUT.png [CELL_WIDTH]\n");
    return 2;
  }
  try {
    const ImageChannels img = crumple::exporters::readExrChannels(argv[1]);
    const int cell = argc > 3 ? std::atoi(argv[3]) : 480;
    std::vector<std::pair<int, ImageRGBA8>> cells;
    crumple::ImageRGBAF beauty(img.width, img.height);
    const char* rgba[4] = {"R", "G", "B", "A"};
    for (int k = 0; k < 4; ++k) {
      const std::vector<float>& c = channel(img, rgba[k]);
      for (std::size_t i = 0; i < c.size(); ++i)
        beauty.pixels[4 * i + static_cast<std::size_t>(k)] = c[i];
    }
    cells.emplace_back(1, crumple::render::toSrgb8(beauty, crumple::Vec3(0.8, 0.82, 0.86)));
    const auto& rr = channel(img, "region.R");
    const auto& rg = channel(img, "region.G");
    const auto& rb = channel(img, "region.B");
    cells.emplace_back(
        2, paint(img, [&](std::size_t i) { return crumple::Vec3(rr[i], rg[i], rb[i]); }));
    const auto& nx = channel(img, "N.X");
    const auto& ny = channel(img, "N.Y");
    const auto& nz = channel(img, "N.Z");
    cells.emplace_back(3, paint(img, [&](std::size_t i) {
                         const crumple::Vec3 n(nx[i], ny[i], nz[i]);
                         return n.squaredNorm() > 0.0 ? crumple::Vec3(0.5 * (n.array() + 1.0))
                                                      : crumple::Vec3(crumple::Vec3::Zero());
                       }));
    const auto& z = channel(img, "Z");
    float lo = 1e30f, hi = 0.0f;
    for (const float d : z)
      if (d < crumple::render::kAovFarDepth) {
        lo = std::min(lo, d);
        hi = std::max(hi, d);
      }
    cells.emplace_back(4, paint(img, [&](std::size_t i) {
                         if (!(z[i] < crumple::render::kAovFarDepth) || !(hi > lo))
                           return crumple::Vec3(crumple::Vec3::Zero());
                         const double t = 1.0 - (z[i] - lo) / (hi - lo);
                         return crumple::Vec3(crumple::Vec3::Constant(0.05 + 0.95 * t * t));
                       }));
    const auto& ob = channel(img, "IndexOB.X");
    cells.emplace_back(5, paint(img, [&](std::size_t i) {
                         return ob[i] == 1.0f   ? crumple::Vec3(1, 1, 1)
                                : ob[i] == 2.0f ? crumple::Vec3(0.2, 0.2, 0.2)
                                                : idColour(ob[i]);
                       }));
    const auto& hd = channel(img, "IndexHandle.X");
    cells.emplace_back(6, paint(img, [&](std::size_t i) { return idColour(hd[i]); }));
    crumple::exporters::writePng(argv[2], crumple::render::makeContactSheet(cells, 3, cell));
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "aov_sheet: %s\n", e.what());
    return 2;
  }
}
