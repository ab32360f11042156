// The Renderer interface's factory and the 8-bit conversions of its images
// (renderer.hpp).
#include "crumple/render/renderer.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "crumple/render/embree_renderer.hpp"
#include "crumple/render/osmesa_renderer.hpp"

namespace crumple::render {

std::unique_ptr<Renderer> makeRenderer(Backend backend, const RendererOptions& options) {
  switch (backend) {
    case Backend::Osmesa:
      return std::make_unique<OsmesaRenderer>(options);
    case Backend::Embree:
      return std::make_unique<EmbreeRenderer>(options);
  }
  throw std::invalid_argument("makeRenderer: unknown backend");
}

ImageRGBA8 toSrgb8(const ImageRGBAF& image, const Vec3& background) {
  ImageRGBA8 out(image.width, image.height);
  const std::uint8_t bg[3] = {linearToSrgb8(background.x()), linearToSrgb8(background.y()),
                              linearToSrgb8(background.z())};
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const float* p = image.at(x, y);
      std::uint8_t* q = out.at(x, y);
      const double a = std::isfinite(p[3]) ? std::clamp(static_cast<double>(p[3]), 0.0, 1.0) : 0.0;
      const auto alpha = static_cast<std::uint8_t>(std::lround(a * 255.0));
      if (alpha > 0) {
        for (int k = 0; k < 3; ++k) q[k] = linearToSrgb8(p[k] / a);
        q[3] = alpha;
      } else {  // also an alpha too small for 8 bits
        for (int k = 0; k < 3; ++k) q[k] = bg[k];
        q[3] = 0;
      }
    }
  return out;
}

RenderedImage::RenderedImage(ImageRGBAF linear, const Vec3& background)
    : background_(background), linear_(std::move(linear)) {}

RenderedImage::RenderedImage(ImageRGBA8 srgb8) : srgb8_(std::move(srgb8)) {}

const ImageRGBAF& RenderedImage::linear() const {
  if (!linear_) linear_ = decodeSrgb8(*srgb8_, /*premultiply=*/true);
  return *linear_;
}

const ImageRGBA8& RenderedImage::srgb8() const {
  if (!srgb8_) srgb8_ = toSrgb8(*linear_, background_);
  return *srgb8_;
}

}  // namespace crumple::render
