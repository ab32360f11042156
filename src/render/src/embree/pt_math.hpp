#pragma once
// Small single-precision vector helpers for the path tracer's inner loop
// (integrator.cpp): plain structs, no allocation, no Eigen overhead.
#include <cmath>
#include <numbers>

namespace crumple::render::pt {

constexpr float kPi = std::numbers::pi_v<float>;
constexpr float kInvPi = std::numbers::inv_pi_v<float>;

struct V3 {
  float x = 0.0f, y = 0.0f, z = 0.0f;
};

inline V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 operator-(V3 a) { return {-a.x, -a.y, -a.z}; }
inline V3 operator*(V3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
inline V3 operator*(float s, V3 a) { return {a.x * s, a.y * s, a.z * s}; }
// Component-wise product (colours).
inline V3 operator*(V3 a, V3 b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
inline V3& operator+=(V3& a, V3 b) { return a = a + b; }
inline V3& operator*=(V3& a, V3 b) { return a = a * b; }
inline V3& operator*=(V3& a, float s) { return a = a * s; }

// Dot product.
inline float dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
// Cross product.
inline V3 cross(V3 a, V3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
// Euclidean length.
inline float length(V3 a) { return std::sqrt(dot(a, a)); }
// Unit vector along a (a must be non-zero).
inline V3 normalize(V3 a) { return a * (1.0f / length(a)); }
// The larger of a and b (b when a is NaN); inlined, unlike std::fmax.
inline float maxf(float a, float b) { return a > b ? a : b; }
// The smaller of a and b (b when a is NaN).
inline float minf(float a, float b) { return a < b ? a : b; }
// Largest component.
inline float maxComponent(V3 a) { return maxf(a.x, maxf(a.y, a.z)); }
// Largest absolute component.
inline float maxAbs(V3 a) { return maxf(std::fabs(a.x), maxf(std::fabs(a.y), std::fabs(a.z))); }
// True when all three components are zero.
inline bool isBlack(V3 a) { return a.x == 0.0f && a.y == 0.0f && a.z == 0.0f; }
// True when all three components are finite.
inline bool isFinite(V3 a) {
  return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
}

// An orthonormal basis (t, b, n) around the unit vector n (Duff et al. 2017,
// "Building an Orthonormal Basis, Revisited").
inline void orthonormalBasis(V3 n, V3& t, V3& b) {
  const float sign = std::copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z);
  const float c = n.x * n.y * a;
  t = {1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x};
  b = {c, sign + n.y * n.y * a, -n.y};
}

// Shirley-Chiu concentric map of the unit square onto the unit disc
// (keeps the stratification of the input points).
inline void concentricDisk(float u1, float u2, float& dx, float& dy) {
  const float a = 2.0f * u1 - 1.0f, b = 2.0f * u2 - 1.0f;
  if (a == 0.0f && b == 0.0f) {
    dx = dy = 0.0f;
    return;
  }
  float r, phi;
  if (std::fabs(a) > std::fabs(b)) {
    r = a;
    phi = 0.25f * kPi * (b / a);
  } else {
    r = b;
    phi = 0.5f * kPi - 0.25f * kPi * (a / b);
  }
  dx = r * std::cos(phi);
  dy = r * std::sin(phi);
}

// A cosine-weighted direction around the unit normal n (pdf cos / pi);
// cosTheta receives its cosine with n.
inline V3 cosineHemisphere(V3 n, float u1, float u2, float& cosTheta) {
  float dx, dy;
  concentricDisk(u1, u2, dx, dy);
  cosTheta = std::sqrt(maxf(1.0f - dx * dx - dy * dy, 0.0f));
  V3 t, b;
  orthonormalBasis(n, t, b);
  return t * dx + b * dy + n * cosTheta;
}

}  // namespace crumple::render::pt
