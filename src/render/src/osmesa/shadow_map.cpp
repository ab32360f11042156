// The rasteriser's shadow-map projection (shadow_map.hpp).
#include "shadow_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace crumple::render::gl {

namespace {

// Rotation whose local -Z is `forward` (a unit vector), local +Y roughly world +Y.
Mat3 frameLookingAlong(const Vec3& forward) {
  const Vec3 a = forward.cwiseAbs();
  const Vec3 up = (a.y() < 0.99) ? Vec3::UnitY() : Vec3::UnitZ();
  const Vec3 right = forward.cross(up).normalized();
  const Vec3 trueUp = right.cross(forward);
  Mat3 r;
  r.col(0) = right;
  r.col(1) = trueUp;
  r.col(2) = -forward;
  return r;
}

// The view matrix of a camera at `eye` with rotation r.
Mat4 viewFromFrame(const Mat3& r, const Vec3& eye) {
  Mat4 v = Mat4::Identity();
  v.topLeftCorner<3, 3>() = r.transpose();
  v.topRightCorner<3, 1>() = -(r.transpose() * eye);
  return v;
}

// OpenGL-style orthographic projection of the box [l, r] x [b, t] x [-f, -n].
Mat4 orthographic(double l, double r, double b, double t, double n, double f) {
  Mat4 m = Mat4::Identity();
  m(0, 0) = 2.0 / (r - l);
  m(1, 1) = 2.0 / (t - b);
  m(2, 2) = -2.0 / (f - n);
  m(0, 3) = -(r + l) / (r - l);
  m(1, 3) = -(t + b) / (t - b);
  m(2, 3) = -(f + n) / (f - n);
  return m;
}

// OpenGL-style square perspective projection of half-angle halfAngle.
Mat4 perspective(double halfAngle, double n, double f) {
  const double c = 1.0 / std::tan(halfAngle);
  Mat4 p = Mat4::Zero();
  p(0, 0) = c;
  p(1, 1) = c;
  p(2, 2) = (f + n) / (n - f);
  p(2, 3) = 2.0 * f * n / (n - f);
  p(3, 2) = -1.0;
  return p;
}

// Orthographic map of a directional light: fitted in x/y to the paper
// (nothing outside it can be shadowed) and in depth to the paper and the
// ground.
ShadowProjection fitDirectional(const Light& kl, const std::vector<Vec3>& receivers, std::size_t nv,
                                int shadowSize) {
  ShadowProjection s;
  const Mat3 r = frameLookingAlong(kl.direction.normalized());
  const Mat4 view = viewFromFrame(r, Vec3::Zero());
  Vec3 lmin = Vec3::Constant(std::numeric_limits<double>::infinity()), lmax = -lmin;
  for (std::size_t i = 0; i < nv; ++i) {
    const Vec3 q = (view * receivers[i].homogeneous()).head<3>();
    lmin = lmin.cwiseMin(q);
    lmax = lmax.cwiseMax(q);
  }
  double zmin = lmin.z(), zmax = lmax.z();
  for (const Vec3& p : receivers) {
    const double z = (view * p.homogeneous()).z();
    zmin = std::min(zmin, z);
    zmax = std::max(zmax, z);
  }
  const double extent = std::max({lmax.x() - lmin.x(), lmax.y() - lmin.y(), 1e-6});
  const double pad = 0.02 * extent + 4.0 * extent / shadowSize;
  const double depthPad = 0.01 * std::max(zmax - zmin, 1e-3);
  const Mat4 proj = orthographic(lmin.x() - pad, lmax.x() + pad, lmin.y() - pad, lmax.y() + pad,
                                 -zmax - depthPad, -zmin + depthPad);
  s.lightViewProj = proj * view;
  s.texelWorld = (extent + 2.0 * pad) / shadowSize;
  return s;
}

// Perspective map from the point (or area light's centre) towards the
// casters' bounding sphere.
ShadowProjection fitPoint(const Light& kl, const std::vector<Vec3>& receivers, std::size_t nv,
                          int shadowSize) {
  ShadowProjection s;
  const Vec3 eye = kl.position;
  double radius = 0.0;
  for (std::size_t i = 0; i < nv; ++i) radius = std::max(radius, receivers[i].norm());
  radius = std::max(radius, 1e-6);
  const double dist = eye.norm();
  const Vec3 forward = dist > 0.0 ? Vec3(-eye / dist) : Vec3(-Vec3::UnitY());
  constexpr double kMaxHalfAngle = 75.0 * std::numbers::pi / 180.0;
  const double half =
      dist > 1.02 * radius
          ? std::min(kMaxHalfAngle, 1.02 * std::asin(radius / dist) + 4.0 / shadowSize)
          : kMaxHalfAngle;
  const double nearPlane = std::max(dist - radius, 1e-3 * radius) * 0.9;
  double farPlane = 2.0 * nearPlane;
  for (const Vec3& p : receivers) farPlane = std::max(farPlane, (p - eye).norm() * 1.01);
  s.lightViewProj =
      perspective(half, nearPlane, farPlane) * viewFromFrame(frameLookingAlong(forward), eye);
  s.texelWorld = 2.0 * std::tan(half) / shadowSize;
  return s;
}

}  // namespace

ShadowProjection fitShadowProjection(const Light& key, const std::vector<Vec3>& receivers,
                                     std::size_t casterCount, int shadowSize) {
  return key.kind == Light::Kind::Directional
             ? fitDirectional(key, receivers, casterCount, shadowSize)
             : fitPoint(key, receivers, casterCount, shadowSize);
}

}  // namespace crumple::render::gl
