// The wind field (sim/air.hpp, docs/AIR.md "Wind and gusts"): the mean
// wind's keys and the gusts' random Fourier modes (Kraichnan 1970).
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "crumple/core/rng.hpp"
#include "crumple/sim/air.hpp"
#include "sin_cos.hpp"

namespace crumple::sim {

namespace {

// The gusts' wavenumbers span this ratio above the largest eddy's.
constexpr double kGustBandwidth = 8.0;

// A unit vector from two uniforms in [0, 1) (uniform on the sphere).
Vec3 unitVector(double a, double b) {
  const double z = 2.0 * a - 1.0;
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  const double phi = 2.0 * std::numbers::pi * b;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

}  // namespace

WindField::WindField(const AirParams& params) : keys_(params.wind) {
  std::stable_sort(keys_.begin(), keys_.end(),
                   [](const WindKey& a, const WindKey& b) { return a.time < b.time; });
  const GustParams& g = params.gusts;
  if (!(g.speed > 0.0) || g.modes <= 0) return;
  const CounterRng rng(g.seed, 0, RngPurpose::Gusts);
  // Wavenumbers with density k^(-5/3) on [k0, kGustBandwidth k0], drawn by
  // inverting its distribution: every mode then carries the same energy.
  const double k0 = 2.0 * std::numbers::pi / g.lengthScale;
  const double k1 = kGustBandwidth * k0;
  const double p0 = std::pow(k0, -2.0 / 3.0), p1 = std::pow(k1, -2.0 / 3.0);
  // Each mode's amplitude: the modes' mean squares add to speed^2.
  const double amplitude = g.speed * std::sqrt(2.0 / static_cast<double>(g.modes));
  modes_.reserve(static_cast<std::size_t>(g.modes));
  for (int i = 0; i < g.modes; ++i) {
    const auto base = static_cast<std::uint64_t>(i) * 8;
    const double k = std::pow(p0 + rng.uniform(base) * (p1 - p0), -1.5);
    const Vec3 dir = unitVector(rng.uniform(base + 1), rng.uniform(base + 2));
    // Divergence-free: the amplitude is perpendicular to the wavevector.
    Vec3 a = dir.cross(unitVector(rng.uniform(base + 3), rng.uniform(base + 4)));
    if (a.norm() < 1e-6) a = dir.unitOrthogonal();
    Mode m;
    m.wavevector = k * dir;
    m.amplitude = amplitude * a.normalized();
    // Decorrelation: angular frequencies around 2 pi / timeScale.
    m.frequency = 2.0 * std::numbers::pi / g.timeScale * (0.5 + rng.uniform(base + 5));
    m.phase = 2.0 * std::numbers::pi * rng.uniform(base + 6);
    modes_.push_back(m);
  }
}

Vec3 WindField::mean(double t) const {
  if (keys_.empty()) return Vec3::Zero();
  if (t <= keys_.front().time) return keys_.front().velocity;
  if (t >= keys_.back().time) return keys_.back().velocity;
  const auto hi = std::upper_bound(keys_.begin(), keys_.end(), t,
                                   [](double tt, const WindKey& k) { return tt < k.time; });
  const auto lo = hi - 1;
  const double span = hi->time - lo->time;
  const double s = span > 0.0 ? (t - lo->time) / span : 1.0;
  return (1.0 - s) * lo->velocity + s * hi->velocity;
}

Vec3 WindField::travel(double t) const {
  // The integral of the piecewise-linear mean wind from 0 to t.
  const auto integral = [this](double a, double b) {
    // Trapezoids between the keys' times inside [a, b] (a <= b).
    Vec3 sum = Vec3::Zero();
    double t0 = a;
    Vec3 w0 = mean(a);
    for (const WindKey& k : keys_) {
      if (k.time <= a) continue;
      if (k.time >= b) break;
      sum += 0.5 * (k.time - t0) * (w0 + k.velocity);
      t0 = k.time;
      w0 = k.velocity;
    }
    return Vec3(sum + 0.5 * (b - t0) * (w0 + mean(b)));
  };
  return t >= 0.0 ? integral(0.0, t) : Vec3(-integral(t, 0.0));
}

Vec3 WindField::at(const Vec3& x, double t) const {
  const Vec3 w = mean(t);
  if (modes_.empty()) return w;
  // Taylor's hypothesis: the eddies travel with the mean wind.
  const Vec3 carried = x - travel(t);
  Vec3 gust = Vec3::Zero();
  for (const Mode& m : modes_)
    gust += m.amplitude * std::cos(m.wavevector.dot(carried) + m.frequency * t + m.phase);
  return w + gust;
}

void WindField::sampleStep(const std::vector<Vec3>& points, double t0, double t1,
                           std::vector<Vec3>& atStart, std::vector<Vec3>& atEnd) const {
  const Vec3 w0 = mean(t0), w1 = mean(t1);
  atStart.assign(points.size(), w0);
  atEnd.assign(points.size(), w1);
  if (modes_.empty()) return;
  const Vec3 travel1 = travel(t1);
  const Vec3 shift = travel1 - travel(t0);
  // phase(t0) = phase(t1) + delta, delta = k . (travel(t1) - travel(t0)) - omega (t1 - t0).
  std::vector<double> cosDelta(modes_.size()), sinDelta(modes_.size());
  for (std::size_t j = 0; j < modes_.size(); ++j) {
    const Mode& m = modes_[j];
    const double delta = m.wavevector.dot(shift) - m.frequency * (t1 - t0);
    cosDelta[j] = std::cos(delta);
    sinDelta[j] = std::sin(delta);
  }
  // Modes outer, points inner, the points' numbers in flat arrays: a mode's
  // phases, their sines and cosines and the sums are each one loop over the
  // points (each point still sums its modes in their order).
  const std::size_t n = points.size();
  std::array<std::vector<double>, 3> carried, g0, g1;
  for (int a = 0; a < 3; ++a) {
    carried[a].resize(n);
    g0[a].assign(n, 0.0);
    g1[a].assign(n, 0.0);
    for (std::size_t i = 0; i < n; ++i) carried[a][i] = points[i](a) - travel1(a);
  }
  std::vector<double> phase(n), sine(n), cosine(n);
  for (std::size_t j = 0; j < modes_.size(); ++j) {
    const Mode& m = modes_[j];
    const double advance = m.frequency * t1 + m.phase;
    const Vec3 k = m.wavevector;
    double largest = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      phase[i] = k.x() * carried[0][i] + k.y() * carried[1][i] + k.z() * carried[2][i] + advance;
      largest = std::max(largest, std::abs(phase[i]));
    }
    if (largest <= kMaxReducedPhase) {
      sinCos(phase.data(), sine.data(), cosine.data(), n);
    } else {
      for (std::size_t i = 0; i < n; ++i) {
        sine[i] = std::sin(phase[i]);
        cosine[i] = std::cos(phase[i]);
      }
    }
    const double cd = cosDelta[j], sd = sinDelta[j];
    for (int a = 0; a < 3; ++a) {
      const double amplitude = m.amplitude(a);
      double* end = g1[a].data();
      double* start = g0[a].data();
      for (std::size_t i = 0; i < n; ++i) {
        end[i] += cosine[i] * amplitude;
        start[i] += (cosine[i] * cd - sine[i] * sd) * amplitude;
      }
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    atStart[i] += Vec3(g0[0][i], g0[1][i], g0[2][i]);
    atEnd[i] += Vec3(g1[0][i], g1[1][i], g1[2][i]);
  }
}

}  // namespace crumple::sim
