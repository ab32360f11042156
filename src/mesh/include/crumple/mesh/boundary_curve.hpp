#pragma once
// A closed 3D curve interpolated through samples along a closed 2D outline:
// the sheet's boundary curve (paper Sec. 6.2: "the 3D coordinates of the
// newly sampled vertices are finally reported on the 3D boundary curve
// using cubic interpolation"; thesis 2.5.2; paper Appendix B). The crumpling
// model reports new ruling endpoints on it (paper/boundary_curve.hpp builds
// it from S_G's outline); the render-time refinement of curved regions
// samples it between S_P's boundary vertices (developable.hpp).
#include <span>
#include <vector>

#include "crumple/core/types.hpp"

namespace crumple::mesh {

// One sample of the curve: outline parameter s (arc length along the outline in
// the pattern, counter-clockwise, from a chosen start) and the
// 3D position of the sheet there.
struct BoundarySample {
  double s = 0.0;
  Vec3 position = Vec3::Zero();
};

// A closed curve s -> x(s) on [0, perimeter), periodic.
//
// Interpolation: piecewise cubic Hermite in s with Bessel tangents (the
// derivative at a sample is that of the parabola through it and its two
// neighbours; for uniform spacing this is Catmull-Rom). It is local, C1,
// passes exactly through the samples, reproduces polynomials of degree 2
// exactly and converges as O(h^3) on smooth curves. Chosen over a periodic
// natural spline because the outline has corners: at a `break` (a corner
// of dS) the curve is only C0 and each side uses a one-sided parabola, so
// the kink of the sheet at a corner does not ring into the neighbouring
// sides. A break with no sample at its parameter (within 1e-12 perimeter)
// is ignored. With one sample the curve is constant, with two it is the
// closed polygon through them.
class BoundaryCurve {
 public:
  // Samples in any order; s is taken modulo `perimeter`. Samples whose
  // parameters coincide (within 1e-12 perimeter) must have the same
  // position (within 1e-9 m) and are merged. Throws std::invalid_argument
  // for no samples, perimeter <= 0, coinciding samples at different
  // positions, and NumericalError (stage "cones") for non-finite input.
  BoundaryCurve(std::vector<BoundarySample> samples, double perimeter,
                std::span<const double> breaks = {});

  // paper Sec. 6.2 (cubic interpolation on the boundary curve): the 3D
  // point at outline parameter s (any real s; wraps periodically).
  Vec3 evaluate(double s) const;
  // d x / d s at s (one-sided from the right at a break).
  Vec3 derivative(double s) const;

  double perimeter() const { return perimeter_; }
  std::size_t sampleCount() const { return s_.size(); }
  // The merged samples, sorted by s in [0, perimeter).
  std::vector<BoundarySample> samples() const;

 private:
  // Index k of the interval [s_k, s_{k+1}) holding s (already wrapped).
  std::size_t interval(double s) const;
  double spacing(std::size_t k) const;  // s_{k+1} - s_k, periodic
  // Where s falls: interval k (from sample k to k1), local u in [0, 1), width h.
  struct Span {
    std::size_t k = 0, k1 = 0;
    double u = 0.0, h = 0.0;
  };
  Span locate(double s) const;

  double perimeter_ = 0.0;
  std::vector<double> s_;
  std::vector<Vec3> x_;
  std::vector<Vec3> tangentIn_;   // derivative at sample k from the left
  std::vector<Vec3> tangentOut_;  // derivative at sample k to the right
};

}  // namespace crumple::mesh
