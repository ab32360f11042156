#include "crumple/sound/spatialize.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <stdexcept>

namespace crumple::sound {

namespace {

// Eq. (4.6): a^3 cos(theta) / R and R / c.
DipolePath path(const Vec3& y, const Vec3& n, double a, const Vec3& x, double c) {
  const Vec3 r = x - y;
  const double distance = r.norm();
  if (!(distance > 0.0))
    throw std::invalid_argument("dipoleResponse: the listener is at the source");
  return {a * a * a * (r / distance).dot(n) / distance, distance / c};
}

}  // namespace

// Thesis 4.3.4, eqs. (4.6)-(4.8).
DipoleResponse dipoleResponse(const DipoleSource& source, const Vec3& listener,
                              const ReflectingPlane* table, double speedOfSound) {
  if (std::abs(source.normal.norm() - 1.0) > 1e-9)
    throw std::invalid_argument("dipoleResponse: the source normal is not a unit vector");
  if (!(source.radius >= 0.0)) throw std::invalid_argument("dipoleResponse: a negative radius");
  if (!(speedOfSound > 0.0)) throw std::invalid_argument("dipoleResponse: speed of sound <= 0");
  DipoleResponse out;
  out.direct = path(source.position, source.normal, source.radius, listener, speedOfSound);
  if (table != nullptr) {
    if (std::abs(table->normal.norm() - 1.0) > 1e-9)
      throw std::invalid_argument("dipoleResponse: the table normal is not a unit vector");
    const Vec3& m = table->normal;
    const Vec3 mirrored = source.position - 2.0 * (source.position - table->point).dot(m) * m;
    const Vec3 normal = source.normal - 2.0 * source.normal.dot(m) * m;
    out.image = path(mirrored, normal, source.radius, listener, speedOfSound);
  }
  return out;
}

// Eq. (4.12), as a power factor per bin.
std::vector<float> powerFactor(const DipoleResponse& response, int fftSize, int sampleRate) {
  if (fftSize < 2 || sampleRate <= 0)
    throw std::invalid_argument("powerFactor: bad FFT size or rate");
  std::vector<float> out(static_cast<std::size_t>(fftSize / 2 + 1));
  const double g = response.direct.gain;
  if (!response.image) {
    std::fill(out.begin(), out.end(), static_cast<float>(g * g));
    return out;
  }
  // g^2 + g~^2 + 2 g g~ cos(k x), x the phase step per bin: cos(k x) as the
  // real part of a unit phasor turned by e^{i x} bin by bin (no cosine per
  // bin; after M / 2 turns its error is ~1e-13).
  const double gi = response.image->gain;
  const double x = 2.0 * std::numbers::pi * sampleRate / fftSize *
                   (response.image->delay - response.direct.delay);
  const std::complex<double> turn(std::cos(x), std::sin(x));
  std::complex<double> phasor(1.0, 0.0);
  for (std::size_t k = 0; k < out.size(); ++k) {
    out[k] = static_cast<float>(g * g + gi * gi + 2.0 * g * gi * phasor.real());
    phasor *= turn;
  }
  return out;
}

// Eq. (4.11).
void addClip(std::span<const float> clip, const DipoleResponse& response, int sampleRate,
             std::int64_t at, std::vector<float>& out) {
  if (at < 0) throw std::invalid_argument("addClip: a negative start");
  const auto start = static_cast<std::size_t>(at);
  double lag = 0.0;  // samples
  if (response.image) {
    lag = (response.image->delay - response.direct.delay) * sampleRate;
    if (!(lag >= 0.0)) lag = 0.0;  // the image is never nearer than the source above the table
  }
  const std::size_t whole = static_cast<std::size_t>(std::floor(lag));
  const double frac = lag - static_cast<double>(whole);
  const std::size_t end = start + clip.size() + (response.image ? whole + 1 : 0);
  if (out.size() < end) out.resize(end, 0.0f);
  for (std::size_t i = 0; i < clip.size(); ++i)
    out[start + i] += static_cast<float>(response.direct.gain * clip[i]);
  if (!response.image) return;
  const double gi = response.image->gain;
  // The image's copy at start + lag: sample i lands between start + whole + i and the next.
  for (std::size_t i = 0; i < clip.size(); ++i) {
    out[start + whole + i] += static_cast<float>(gi * (1.0 - frac) * clip[i]);
    out[start + whole + i + 1] += static_cast<float>(gi * frac * clip[i]);
  }
}

}  // namespace crumple::sound
