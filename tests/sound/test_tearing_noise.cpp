// The sound of a tear (thesis 4.4.1).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "crumple/sound/tearing_noise.hpp"

using namespace crumple::sound;

namespace {

std::vector<float> tear(double speed, std::size_t n, double alpha = 100.0, int id = 0) {
  TearingNoiseParams p;
  p.alpha = alpha;
  TearingNoise noise(9, id, p);
  std::vector<float> out;
  const std::vector<double> speeds(n, speed);
  noise.add(0, speeds, out);
  return out;
}

double rms(const std::vector<float>& x) {
  double s = 0.0;
  for (float v : x) s += static_cast<double>(v) * v;
  return std::sqrt(s / static_cast<double>(x.size()));
}

double crest(const std::vector<float>& x) {
  double peak = 0.0;
  for (float v : x) peak = std::max(peak, static_cast<double>(std::abs(v)));
  return peak / rms(x);
}

// Samples above a tenth of the largest: the crackle's bursts.
int bursts(const std::vector<float>& x) {
  double peak = 0.0;
  for (float v : x) peak = std::max(peak, static_cast<double>(std::abs(v)));
  int n = 0;
  for (std::size_t i = 1; i < x.size(); ++i)
    if (std::abs(x[i]) > 0.1 * peak && std::abs(x[i - 1]) <= 0.1 * peak) ++n;
  return n;
}

}  // namespace

// A still tip is silent; a tip twice as fast is twice as loud (the
// amplitude), and its crackle plays twice as fast (the pitch): about twice
// the bursts per second.
TEST(TearingNoise, AmplitudeAndPitchFollowTheSpeed) {
  const std::size_t second = 48000;
  const std::vector<float> still = tear(0.0, second);
  EXPECT_TRUE(std::all_of(still.begin(), still.end(), [](float v) { return v == 0.0f; }));
  const std::vector<float> slow = tear(0.05, 4 * second), fast = tear(0.1, 4 * second);
  const double loud = rms(fast) / rms(slow),
               quick = static_cast<double>(bursts(fast)) / bursts(slow);
  std::printf(
      "[ measure ] tearing noise at 5 and 10 cm/s: RMS x %.3f, bursts per second x %.3f "
      "(%d and %d in 4 s)\n",
      loud, quick, bursts(slow), bursts(fast));
  EXPECT_NEAR(loud, 2.0, 0.2);
  EXPECT_NEAR(quick, 2.0, 0.3);
}

// alpha turns white noise into a crackle: at the thesis' 100 the crest
// factor is far above white noise's (alpha = 1: n r, the product of two
// uniforms, RMS 1/3 and peaks near 1: a crest factor near 3).
TEST(TearingNoise, AlphaMakesACrackle) {
  const std::vector<float> white = tear(0.1, 48000, 1.0), crackle = tear(0.1, 48000, 100.0);
  std::printf("[ measure ] tearing noise crest factor: %.2f at alpha 1, %.2f at alpha 100\n",
              crest(white), crest(crackle));
  EXPECT_NEAR(crest(white), 3.0, 0.3);
  EXPECT_GT(crest(crackle), 3.0 * crest(white));
}

// Made in pieces, the noise is the noise made at once; another tear's differs.
TEST(TearingNoise, GoesOnWhereItStoppedAndRepeats) {
  std::vector<double> speeds(3000);
  for (std::size_t i = 0; i < speeds.size(); ++i) speeds[i] = 0.02 + 1e-4 * static_cast<double>(i);
  TearingNoise whole(4, 1), pieces(4, 1), other(4, 2);
  std::vector<float> a, b, c;
  whole.add(0, speeds, a);
  pieces.add(0, std::span(speeds).first(1234), b);
  pieces.add(1234, std::span(speeds).subspan(1234), b);
  other.add(0, speeds, c);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  EXPECT_THROW(pieces.add(10, speeds, b), std::invalid_argument);
  TearingNoise bad(4, 3);
  EXPECT_THROW(bad.add(0, std::vector<double>{-1.0}, b), std::invalid_argument);
  TearingNoiseParams p;
  p.alpha = 0.5;
  EXPECT_THROW(TearingNoise(1, 0, p), std::invalid_argument);
}
