#pragma once
// Spatialisation (thesis 4.3.4, eqs. (4.6)-(4.12)): each
// resonator radiates as a small vibrating disk, a dipole of pressure
// a^3 cos(theta) / R A(t - R / c); a rigid table adds the image dipole
// (position and normal mirrored in its plane). Crumpling clips are placed
// in the time domain with the image's copy delayed by (R~ - R) / c (eq.
// 4.11); friction spectra are multiplied by the power of eq. (4.12)'s
// factor, whose comb notches move with the height above the table.
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "crumple/core/types.hpp"

namespace crumple::sound {

inline constexpr double kSpeedOfSound = 343.0;  // m/s, air at 20 C

// A resonator as a vibrating disk (thesis Fig. 4.14).
struct DipoleSource {
  Vec3 position = Vec3::Zero();  // y: its centre (m)
  Vec3 normal = Vec3::UnitY();   // n: unit
  double radius = 0.01;          // a (m)
};

// A rigid reflecting plane (the table): a point on it and its unit normal.
struct ReflectingPlane {
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::UnitY();
};

// One path from the source to the listener: a^3 cos(theta) / R, and R / c.
struct DipolePath {
  double gain = 0.0;
  double delay = 0.0;  // s
};

struct DipoleResponse {
  DipolePath direct;
  std::optional<DipolePath> image;  // with a table
};

// Eqs. (4.6) and (4.8): the direct path and, with a table, the image's
// (the source and its normal mirrored in the plane). Throws
// std::invalid_argument for a listener at the source, a non-unit normal or
// a negative radius.
DipoleResponse dipoleResponse(const DipoleSource& source, const Vec3& listener,
                              const ReflectingPlane* table, double speedOfSound = kSpeedOfSound);

// Eq. (4.12) for friction spectra: |g e^{i w R/c} + g~ e^{i w R~/c}|^2 at
// the centre of every bin k of an M-point FFT at `sampleRate` (w = 2 pi k
// rate / M), M / 2 + 1 values: the factor a friction power spectrum is
// multiplied by.
std::vector<float> powerFactor(const DipoleResponse& response, int fftSize, int sampleRate);

// Eq. (4.11) for crumpling clips: adds g * clip at sample `at` and, with
// the image, g~ * clip delayed by (R~ - R) / c (a fractional delay, by
// linear interpolation) into `out` (grown as needed).
void addClip(std::span<const float> clip, const DipoleResponse& response, int sampleRate,
             std::int64_t at, std::vector<float>& out);

}  // namespace crumple::sound
