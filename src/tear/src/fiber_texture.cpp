#include "crumple/tear/fiber_texture.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "crumple/core/rng.hpp"

namespace crumple::tear {

namespace {

// Perlin's quintic fade (Perlin 2002, "Improving noise").
double fade(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

// A unit gradient per lattice point and octave, from the counter-based RNG:
// a pure function of (seed, octave, x, y).
Vec2 gradient(const CounterRng& rng, int octave, std::int64_t x, std::int64_t y) {
  const std::uint64_t key = CounterRng::mix(static_cast<std::uint64_t>(x) * 0x9E3779B97F4A7C15ULL ^
                                            CounterRng::mix(static_cast<std::uint64_t>(y))) +
                            static_cast<std::uint64_t>(octave);
  const double angle = 2.0 * std::numbers::pi * rng.uniform(key);
  return {std::cos(angle), std::sin(angle)};
}

// 2D gradient noise at q (lattice units), in about [-0.7, 0.7].
double perlin(const CounterRng& rng, int octave, const Vec2& q) {
  const double fx = std::floor(q.x()), fy = std::floor(q.y());
  const auto x0 = static_cast<std::int64_t>(fx), y0 = static_cast<std::int64_t>(fy);
  const double dx = q.x() - fx, dy = q.y() - fy;
  auto corner = [&](std::int64_t i, std::int64_t j) {
    return gradient(rng, octave, x0 + i, y0 + j)
        .dot(Vec2(dx - static_cast<double>(i), dy - static_cast<double>(j)));
  };
  const double u = fade(dx), v = fade(dy);
  const double bottom = corner(0, 0) + u * (corner(1, 0) - corner(0, 0));
  const double top = corner(0, 1) + u * (corner(1, 1) - corner(0, 1));
  return bottom + v * (top - bottom);
}

}  // namespace

FiberTexture::FiberTexture(const Vec2& origin, const Vec2& size, const FiberTextureParams& params)
    : params_(params), origin_(origin) {
  const auto bad = [](const char* what) {
    throw std::invalid_argument(std::string("FiberTexture: ") + what);
  };
  if (!origin.allFinite() || !size.allFinite() || !(size.minCoeff() > 0.0))
    bad("the pattern rectangle must be finite with positive sides");
  if (!(params.texelSize > 0.0) || !std::isfinite(params.texelSize)) bad("texel size must be > 0");
  if (!(params.featureSize > 0.0) || !std::isfinite(params.featureSize))
    bad("feature size must be > 0");
  if (params.octaves < 1 || params.octaves > 16) bad("octaves must be 1 ... 16");
  if (!(params.persistence > 0.0) || !(params.persistence <= 1.0))
    bad("persistence must be in (0, 1]");
  if (!(params.anisotropy >= 1.0) || !std::isfinite(params.anisotropy))
    bad("anisotropy must be >= 1");
  if (!(params.fiberDirection.norm() > 0.0) || !params.fiberDirection.allFinite())
    bad("fiber direction must be a non-zero vector");
  const double w = std::ceil(size.x() / params.texelSize);
  const double h = std::ceil(size.y() / params.texelSize);
  if (w * h > 64.0 * 1024.0 * 1024.0) bad("more than 64 M texels: raise the texel size");
  width_ = std::max(1, static_cast<int>(w));
  height_ = std::max(1, static_cast<int>(h));

  // Lattice coordinates: along the fibers the features are `anisotropy`
  // times longer.
  const Vec2 along = params.fiberDirection.normalized();
  const Vec2 across(-along.y(), along.x());
  const CounterRng rng(params.seed, 0, RngPurpose::FiberTexture);
  values_.resize(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_));
  for (int j = 0; j < height_; ++j) {
    for (int i = 0; i < width_; ++i) {
      const Vec2 p = centre(i, j);
      const Vec2 q(p.dot(along) / params.anisotropy, p.dot(across));
      double value = 0.0, amplitude = 1.0, wavelength = params.featureSize;
      for (int o = 0; o < params.octaves; ++o) {
        value += amplitude * perlin(rng, o, q / wavelength);
        amplitude *= params.persistence;
        wavelength *= 0.5;
      }
      values_[static_cast<std::size_t>(j) * static_cast<std::size_t>(width_) +
              static_cast<std::size_t>(i)] = value;
    }
  }
  // Normalised to [0, 1] over the texture.
  const auto [lo, hi] = std::minmax_element(values_.begin(), values_.end());
  const double low = *lo, span = *hi - *lo;
  for (double& v : values_) v = span > 0.0 ? (v - low) / span : 0.5;
}

Vec2 FiberTexture::centre(int i, int j) const {
  return origin_ + params_.texelSize * Vec2(i + 0.5, j + 0.5);
}

std::array<int, 2> FiberTexture::texelOf(const Vec2& p) const {
  const Vec2 q = (p - origin_) / params_.texelSize;
  const int i = std::clamp(static_cast<int>(std::floor(q.x())), 0, width_ - 1);
  const int j = std::clamp(static_cast<int>(std::floor(q.y())), 0, height_ - 1);
  return {i, j};
}

double FiberTexture::sample(const Vec2& p) const {
  const Vec2 q = (p - origin_) / params_.texelSize - Vec2(0.5, 0.5);
  const double x = std::clamp(q.x(), 0.0, static_cast<double>(width_ - 1));
  const double y = std::clamp(q.y(), 0.0, static_cast<double>(height_ - 1));
  const int i = std::min(static_cast<int>(x), width_ - 1);
  const int j = std::min(static_cast<int>(y), height_ - 1);
  const int i1 = std::min(i + 1, width_ - 1), j1 = std::min(j + 1, height_ - 1);
  const double fx = x - i, fy = y - j;
  const double bottom = texel(i, j) + fx * (texel(i1, j) - texel(i, j));
  const double top = texel(i, j1) + fx * (texel(i1, j1) - texel(i, j1));
  return bottom + fy * (top - bottom);
}

}  // namespace crumple::tear
