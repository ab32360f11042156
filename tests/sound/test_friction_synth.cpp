// Friction noise from power spectra: its level follows the
// spectrum, its colour follows the spectrum, its blocks join without clicks,
// and it repeats for a seed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <numeric>
#include <vector>

#include "crumple/sound/friction_synth.hpp"

using namespace crumple::sound;

namespace {

constexpr int kM = 2048;

// A power spectrum of M/2 + 1 bins: a resonance at `peak` (bin) of width
// `width` bins over a floor.
std::vector<float> resonance(double peak, double width, double floor = 0.01) {
  std::vector<float> p(kM / 2 + 1);
  for (std::size_t k = 0; k < p.size(); ++k)
    p[k] = static_cast<float>(floor + 1.0 / (1.0 + std::pow((k - peak) / width, 2.0)));
  return p;
}

std::vector<float> synthesize(const std::vector<float>& power, int blocks, std::uint64_t seed = 3) {
  FrictionSynth synth(kM, seed);
  std::vector<float> out;
  for (int b = 0; b < blocks; ++b) synth.addBlock(b, power, out);
  return out;
}

// The samples where every one is the overlap of two blocks.
std::vector<float> steady(const std::vector<float>& x, int blocks) {
  return {x.begin() + kM / 2, x.begin() + static_cast<std::ptrdiff_t>(blocks) * (kM / 2)};
}

double variance(const std::vector<float>& x) {
  const double mean = std::accumulate(x.begin(), x.end(), 0.0) / static_cast<double>(x.size());
  double v = 0.0;
  for (float s : x) v += (s - mean) * (s - mean);
  return v / static_cast<double>(x.size());
}

// Spectral centroid (Hz at 48 kHz) of x from periodograms of 256-sample
// Hann-windowed segments.
double centroid(const std::vector<float>& x) {
  constexpr int n = 256;
  std::vector<double> power(n / 2 + 1, 0.0);
  for (std::size_t start = 0; start + n <= x.size(); start += n) {
    for (int k = 0; k <= n / 2; ++k) {
      double re = 0.0, im = 0.0;
      for (int i = 0; i < n; ++i) {
        const double w = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * i / n);
        const double a = 2.0 * std::numbers::pi * k * i / n;
        re += w * x[start + static_cast<std::size_t>(i)] * std::cos(a);
        im -= w * x[start + static_cast<std::size_t>(i)] * std::sin(a);
      }
      power[static_cast<std::size_t>(k)] += re * re + im * im;
    }
  }
  double num = 0.0, den = 0.0;
  for (int k = 0; k <= n / 2; ++k) {
    num += power[static_cast<std::size_t>(k)] * k * 48000.0 / n;
    den += power[static_cast<std::size_t>(k)];
  }
  return num / den;
}

}  // namespace

// For a constant spectrum the noise's variance is (P_0 + P_M/2 + 2 sum P_k) / M^2.
TEST(FrictionSynth, ItsVarianceFollowsTheSpectrum) {
  const std::vector<float> p = resonance(100.0, 20.0);
  double expected = p.front() + p.back();
  for (std::size_t k = 1; k + 1 < p.size(); ++k) expected += 2.0 * p[k];
  expected /= static_cast<double>(kM) * kM;
  const int blocks = 200;
  const double v = variance(steady(synthesize(p, blocks), blocks));
  EXPECT_NEAR(v / expected, 1.0, 0.05) << v << " vs " << expected;
  // Four times the power, twice the amplitude.
  std::vector<float> p4 = p;
  for (float& x : p4) x *= 4.0f;
  EXPECT_NEAR(variance(steady(synthesize(p4, blocks), blocks)) / v, 4.0, 1e-3);
}

// The noise's colour follows the spectrum: a resonance four times higher
// moves the centroid up (the shrinking resonator of thesis Fig. 4.16).
TEST(FrictionSynth, ItsColourFollowsTheSpectrum) {
  const int blocks = 60;
  const double low = centroid(steady(synthesize(resonance(40.0, 8.0, 0.0), blocks), blocks));
  const double high = centroid(steady(synthesize(resonance(160.0, 32.0, 0.0), blocks), blocks));
  // Bin k is k * 48000 / 2048 Hz: 937.5 Hz and 3750 Hz.
  EXPECT_NEAR(low, 937.5, 250.0);
  EXPECT_GT(high, 2.5 * low);
}

// No clicks at block joins: in a steady stretch, the
// largest sample-to-sample step at a join stays within 4 standard
// deviations of the stretch's own steps.
TEST(FrictionSynth, BlocksJoinWithoutClicks) {
  const int blocks = 96;  // about 2 s at 48 kHz
  const std::vector<float> x = steady(synthesize(resonance(300.0, 60.0), blocks), blocks);
  std::vector<double> steps(x.size() - 1);
  for (std::size_t i = 0; i + 1 < x.size(); ++i) steps[i] = x[i + 1] - x[i];
  const double sd = std::sqrt(std::accumulate(steps.begin(), steps.end(), 0.0,
                                              [](double a, double d) { return a + d * d; }) /
                              static_cast<double>(steps.size()));
  double atJoins = 0.0;
  for (std::size_t j = 0; j < steps.size(); j += kM / 2)
    for (std::size_t i = (j > 0 ? j - 1 : 0); i <= j + 1 && i < steps.size(); ++i)
      atJoins = std::max(atJoins, std::abs(steps[i]));
  std::printf("[ measure ] friction noise: largest step at the %zu joins %.2f sd of the steps\n",
              steps.size() / (kM / 2) + 1, atJoins / sd);
  EXPECT_LE(atJoins, 4.0 * sd);
}

TEST(FrictionSynth, RepeatsForASeedAndRefusesBadSpectra) {
  const std::vector<float> p = resonance(100.0, 20.0);
  EXPECT_EQ(synthesize(p, 8, 5), synthesize(p, 8, 5));
  EXPECT_NE(synthesize(p, 8, 5), synthesize(p, 8, 6));
  FrictionSynth synth(kM, 1);
  std::vector<float> out;
  EXPECT_THROW(synth.addBlock(0, std::vector<float>(kM / 2), out), std::invalid_argument);
  std::vector<float> bad = p;
  bad[7] = -1.0f;
  EXPECT_THROW(synth.addBlock(0, bad, out), std::invalid_argument);
  EXPECT_THROW(FrictionSynth(1000, 1), std::invalid_argument);
}
