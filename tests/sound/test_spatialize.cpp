// Spatialisation (thesis 4.3.4): the dipole's lobe and
// distance law, the table's image source, its comb in friction spectra
// (the notches move with the height above the table: the issue's
// acceptance) and its delayed copy of crumpling clips.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "crumple/sound/spatialize.hpp"

using namespace crumple;
using namespace crumple::sound;

namespace {

constexpr int kM = 2048, kRate = 48000;

// The frequencies (Hz) of the local minima of the power factor above 0 Hz.
std::vector<double> notches(const std::vector<float>& p) {
  std::vector<double> out;
  for (std::size_t k = 1; k + 1 < p.size(); ++k)
    if (p[k] < p[k - 1] && p[k] <= p[k + 1]) out.push_back(static_cast<double>(k) * kRate / kM);
  return out;
}

}  // namespace

// Eq. (4.6): a^3 cos(theta) / R, R / c.
TEST(Spatialize, TheDipolesLobeAndDistanceLaw) {
  DipoleSource s;
  s.radius = 0.02;
  const double a3 = 0.02 * 0.02 * 0.02;
  const auto above = dipoleResponse(s, Vec3(0, 2, 0), nullptr);
  EXPECT_NEAR(above.direct.gain, a3 / 2.0, 1e-15);
  EXPECT_NEAR(above.direct.delay, 2.0 / kSpeedOfSound, 1e-15);
  EXPECT_FALSE(above.image.has_value());
  EXPECT_NEAR(dipoleResponse(s, Vec3(0, -1, 0), nullptr).direct.gain, -a3, 1e-15);
  EXPECT_NEAR(dipoleResponse(s, Vec3(1, 0, 0), nullptr).direct.gain, 0.0, 1e-15);
  EXPECT_NEAR(dipoleResponse(s, Vec3(1, 1, 0), nullptr).direct.gain,
              a3 * std::cos(std::numbers::pi / 4) / std::sqrt(2.0), 1e-15);
  EXPECT_THROW(dipoleResponse(s, s.position, nullptr), std::invalid_argument);
}

// The table's image makes a comb in a friction spectrum: its first notch
// sits where the two paths are half a period apart (a whole one when the
// image is in opposite phase), its notches are 1 / (R~ - R) * c apart, and
// they close up as the sheet rises.
TEST(Spatialize, TheCombsNotchesMoveWithTheHeight) {
  const ReflectingPlane table;  // y = 0
  const Vec3 listener(0.5, 0.4, 0.3);
  double previous = 1e9;
  for (const double height : {0.03, 0.05, 0.08, 0.12}) {
    DipoleSource s;
    s.position = Vec3(0, height, 0);
    s.normal = Vec3(1, 1, 0).normalized();  // a sheet standing at 45 degrees
    const DipoleResponse r = dipoleResponse(s, listener, &table);
    ASSERT_TRUE(r.image.has_value());
    const double lag = r.image->delay - r.direct.delay;
    const bool opposite = r.direct.gain * r.image->gain < 0.0;
    const std::vector<double> n = notches(powerFactor(r, kM, kRate));
    ASSERT_GE(n.size(), 2u);
    const double spacing = n[1] - n[0];
    std::printf(
        "[ measure ] comb at %.0f mm above the table: notches at %.0f, %.0f Hz ... "
        "(path difference %.1f mm: first %.0f Hz, spacing %.0f Hz expected)\n",
        1e3 * height, n[0], n[1], 1e3 * lag * kSpeedOfSound, opposite ? 1.0 / lag : 0.5 / lag,
        1.0 / lag);
    EXPECT_NEAR(n[0], opposite ? 1.0 / lag : 0.5 / lag, 1.0 * kRate / kM);
    EXPECT_NEAR(spacing, 1.0 / lag, 2.0 * kRate / kM);
    EXPECT_LT(spacing, previous) << "the notches close up as the sheet rises";
    previous = spacing;
  }
  // No table, no comb.
  DipoleSource s;
  s.position = Vec3(0, 0.05, 0);
  const auto flat = powerFactor(dipoleResponse(s, listener, nullptr), kM, kRate);
  for (float v : flat) EXPECT_FLOAT_EQ(v, flat.front());
}

// Eq. (4.11): the clip at its sample with the direct gain, its image's copy
// (R~ - R) / c later with the image's gain, split between two samples.
TEST(Spatialize, AClipGetsItsImagesDelayedCopy) {
  const ReflectingPlane table;
  DipoleSource s;
  s.position = Vec3(0, 0.07, 0);
  const DipoleResponse r = dipoleResponse(s, Vec3(0.3, 0.5, 0.2), &table);
  std::vector<float> out;
  const std::vector<float> impulse{1.0f};
  addClip(impulse, r, kRate, 100, out);
  const double lag = (r.image->delay - r.direct.delay) * kRate;
  const auto whole = static_cast<std::size_t>(std::floor(lag));
  EXPECT_FLOAT_EQ(out[100], static_cast<float>(r.direct.gain));
  EXPECT_NEAR(out[100 + whole] + out[101 + whole], r.image->gain, 1e-12);
  EXPECT_NEAR(out[101 + whole] / r.image->gain, lag - whole, 1e-6);
  double elsewhere = 0.0;
  for (std::size_t i = 0; i < out.size(); ++i)
    if (i != 100 && i != 100 + whole && i != 101 + whole) elsewhere += std::abs(out[i]);
  EXPECT_EQ(elsewhere, 0.0);
}
