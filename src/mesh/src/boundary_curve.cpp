#include "crumple/mesh/boundary_curve.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "crumple/core/error.hpp"
#include "crumple/core/index.hpp"

namespace crumple::mesh {

namespace {

double wrapParameter(double s, double perimeter) {
  double w = std::fmod(s, perimeter);
  if (w < 0.0) w += perimeter;
  if (w >= perimeter) w = 0.0;  // fmod of a tiny negative number rounds up to perimeter
  return w;
}

// Periodic distance between two parameters.
double periodicDistance(double a, double b, double perimeter) {
  const double d = std::abs(wrapParameter(a - b, perimeter));
  return std::min(d, perimeter - d);
}

}  // namespace

// paper Sec. 6.2 / thesis 2.5.2: the boundary curve the resampled ruling
// endpoints are reported on; Bessel-tangent cubic Hermite (see header).
BoundaryCurve::BoundaryCurve(std::vector<BoundarySample> samples, double perimeter,
                             std::span<const double> breaks)
    : perimeter_(perimeter) {
  if (!(perimeter > 0.0) || !std::isfinite(perimeter)) {
    throw std::invalid_argument("BoundaryCurve: the perimeter must be positive and finite");
  }
  if (samples.empty()) throw std::invalid_argument("BoundaryCurve: no samples");
  for (BoundarySample& sample : samples) {
    if (!std::isfinite(sample.s) || !sample.position.allFinite()) {
      throw NumericalError("cones", "boundary curve sample is not finite");
    }
    sample.s = wrapParameter(sample.s, perimeter);
  }
  std::sort(samples.begin(), samples.end(),
            [](const BoundarySample& a, const BoundarySample& b) { return a.s < b.s; });
  const double mergeTol = 1e-12 * perimeter;
  for (const BoundarySample& sample : samples) {
    if (!s_.empty() && sample.s - s_.back() <= mergeTol) {
      if ((sample.position - x_.back()).norm() > 1e-9) {
        throw std::invalid_argument(
            "BoundaryCurve: two samples at the same parameter with different positions");
      }
      continue;
    }
    s_.push_back(sample.s);
    x_.push_back(sample.position);
  }
  // The last sample may coincide with the first across the wrap.
  if (s_.size() > 1 && perimeter - s_.back() + s_.front() <= mergeTol) {
    if ((x_.back() - x_.front()).norm() > 1e-9) {
      throw std::invalid_argument(
          "BoundaryCurve: two samples at the same parameter with different positions");
    }
    s_.pop_back();
    x_.pop_back();
  }

  const std::size_t n = s_.size();
  tangentIn_.assign(n, Vec3::Zero());
  tangentOut_.assign(n, Vec3::Zero());
  if (n == 1) return;

  std::vector<char> isBreak(n, 0);
  for (double b : breaks) {
    if (!std::isfinite(b)) throw NumericalError("cones", "boundary curve break is not finite");
    for (std::size_t k = 0; k < n; ++k) {
      if (periodicDistance(s_[k], b, perimeter) <= mergeTol) isBreak[k] = 1;
    }
  }
  const auto next = [n](std::size_t k) { return (k + 1) % n; };
  const auto prev = [n](std::size_t k) { return (k + n - 1) % n; };
  // Chord slopes Delta_k = (x_{k+1} - x_k) / h_k.
  std::vector<Vec3> delta(n);
  for (std::size_t k = 0; k < n; ++k) delta[k] = (x_[next(k)] - x_[k]) / spacing(k);
  if (n == 2) {
    for (std::size_t k = 0; k < n; ++k) {
      tangentOut_[k] = delta[k];
      tangentIn_[k] = delta[prev(k)];
    }
    return;
  }
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t km = prev(k);
    const double hm = spacing(km);
    const double h = spacing(k);
    if (!isBreak[k]) {
      // Derivative of the parabola through x_{k-1}, x_k, x_{k+1} at s_k.
      const Vec3 m = (hm * delta[k] + h * delta[km]) / (hm + h);
      tangentIn_[k] = m;
      tangentOut_[k] = m;
      continue;
    }
    // One-sided parabolas on each side of a corner.
    if (isBreak[next(k)]) {
      tangentOut_[k] = delta[k];
    } else {
      const double h1 = spacing(next(k));
      tangentOut_[k] = delta[k] - h * (delta[next(k)] - delta[k]) / (h + h1);
    }
    if (isBreak[km]) {
      tangentIn_[k] = delta[km];
    } else {
      const double hmm = spacing(prev(km));
      tangentIn_[k] = delta[km] + hm * (delta[km] - delta[prev(km)]) / (hmm + hm);
    }
  }
}

double BoundaryCurve::spacing(std::size_t k) const {
  const std::size_t n = s_.size();
  return k + 1 < n ? s_[k + 1] - s_[k] : s_.front() + perimeter_ - s_[k];
}

std::size_t BoundaryCurve::interval(double s) const {
  const auto it = std::upper_bound(s_.begin(), s_.end(), s);
  if (it == s_.begin()) return s_.size() - 1;  // before the first sample: the wrapping interval
  return idx(it - s_.begin()) - 1;
}

BoundaryCurve::Span BoundaryCurve::locate(double s) const {
  double w = wrapParameter(s, perimeter_);
  Span span;
  span.k = interval(w);
  span.k1 = (span.k + 1) % s_.size();
  if (w < s_[span.k]) w += perimeter_;
  span.h = spacing(span.k);
  span.u = (w - s_[span.k]) / span.h;
  return span;
}

// paper Sec. 6.2: cubic interpolation of the 3D boundary curve at s.
Vec3 BoundaryCurve::evaluate(double s) const {
  if (!std::isfinite(s))
    throw NumericalError("cones", "boundary curve evaluated at a non-finite parameter");
  if (s_.size() == 1) return x_.front();
  const auto [k, k1, u, h] = locate(s);
  const double u2 = u * u;
  const double u3 = u2 * u;
  const double h00 = 2.0 * u3 - 3.0 * u2 + 1.0;
  const double h10 = u3 - 2.0 * u2 + u;
  const double h01 = -2.0 * u3 + 3.0 * u2;
  const double h11 = u3 - u2;
  const Vec3 x = h00 * x_[k] + h10 * h * tangentOut_[k] + h01 * x_[k1] + h11 * h * tangentIn_[k1];
  if (!x.allFinite()) throw NumericalError("cones", "boundary curve produced a non-finite point");
  return x;
}

Vec3 BoundaryCurve::derivative(double s) const {
  if (!std::isfinite(s))
    throw NumericalError("cones", "boundary curve evaluated at a non-finite parameter");
  if (s_.size() == 1) return Vec3::Zero();
  const auto [k, k1, u, h] = locate(s);
  const double u2 = u * u;
  const double d00 = (6.0 * u2 - 6.0 * u) / h;
  const double d10 = 3.0 * u2 - 4.0 * u + 1.0;
  const double d01 = (-6.0 * u2 + 6.0 * u) / h;
  const double d11 = 3.0 * u2 - 2.0 * u;
  return d00 * x_[k] + d10 * tangentOut_[k] + d01 * x_[k1] + d11 * tangentIn_[k1];
}

std::vector<BoundarySample> BoundaryCurve::samples() const {
  std::vector<BoundarySample> out(s_.size());
  for (std::size_t k = 0; k < s_.size(); ++k) out[k] = {s_[k], x_[k]};
  return out;
}

}  // namespace crumple::mesh
