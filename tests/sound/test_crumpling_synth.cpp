// A crumpling event's sound and the soundtrack's sync
// (the acceptance: one event placed at a known frame has its onset
// in the WAV within 1 ms of that frame's time).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "crumple/sound/crumpling_synth.hpp"
#include "crumple/sound/database.hpp"
#include "sound_db_fixture.hpp"

using namespace crumple;
using namespace crumple::sound;

namespace {

// The first sample whose magnitude reaches `fraction` of the largest.
std::size_t onset(const std::vector<float>& x, double fraction = 0.05) {
  double peak = 0.0;
  for (float v : x) peak = std::max(peak, static_cast<double>(std::abs(v)));
  for (std::size_t i = 0; i < x.size(); ++i)
    if (std::abs(x[i]) >= fraction * peak) return i;
  return x.size();
}

DipoleResponse overTheTable() {
  DipoleSource s;
  s.position = Vec3(0.0, 0.04, 0.0);
  s.radius = 0.03;
  const ReflectingPlane table;
  return dipoleResponse(s, Vec3(0.4, 0.5, 0.6), &table);
}

}  // namespace

// One event at frame 37 of a 24 fps shot, written to a 24-bit WAV and read
// back: its onset is within 1 ms of 37 / 24 s.
TEST(CrumplingSynth, AnEventSoundsAtItsFrameWithinAMillisecond) {
  const crumple::testing::DatabaseScratch s;
  crumple::testing::writeDatabase(s.dir);
  const SoundDatabase db = SoundDatabase::load(s.dir);
  {
    const int rate = 48000;
    const Timeline timeline(rate, 24.0, 48);
    CrumplingSound e;
    e.time = 37.0 / 24.0;
    e.amplitude = 20.0;
    e.ruling = 0.03;
    e.border = 0.05;
    e.response = overTheTable();
    std::vector<float> out(static_cast<std::size_t>(timeline.sampleCount()), 0.0f);
    ASSERT_TRUE(addCrumplingSound(db, e, timeline, 1, 0, out));
    out.resize(static_cast<std::size_t>(timeline.sampleCount()));
    Audio a;
    a.sampleRate = rate;
    a.channels = {out};
    ASSERT_EQ(writeWav(s.dir / "sync.wav", a, SampleFormat::Pcm24), 0);
    const Audio back = readWav(s.dir / "sync.wav");
    ASSERT_EQ(back.sampleCount(), static_cast<std::size_t>(timeline.sampleCount()));
    const double heard = static_cast<double>(onset(back.channels[0])) / rate;
    std::printf(
        "[ measure ] sync: an event at frame 37 (%.6f s) starts at %.6f s in the WAV "
        "(%+.3f ms)\n",
        e.time, heard, 1e3 * (heard - e.time));
    EXPECT_NEAR(heard, e.time, 1e-3);
  }
}

// The cell follows the resonator (l_c = 0: the constrained cell), the
// amplitude scales the clip, the variant is the seed's, and nothing is
// added where the database has no clip.
TEST(CrumplingSynth, TheCellTheAmplitudeAndTheVariant) {
  const crumple::testing::DatabaseScratch s;
  crumple::testing::writeDatabase(s.dir);
  const SoundDatabase db = SoundDatabase::load(s.dir);
  const Timeline timeline(48000, 24.0, 24);
  DipoleSource src;
  src.position = Vec3(0, 1, 0);
  const DipoleResponse straight = dipoleResponse(src, Vec3(0, 2, 0), nullptr);
  CrumplingSound e;
  e.amplitude = 1.0;
  e.response = straight;
  const auto play = [&](double lr, double lc, double amplitude, std::uint64_t seed) {
    CrumplingSound x = e;
    x.ruling = lr;
    x.border = lc;
    x.amplitude = amplitude;
    std::vector<float> out;
    addCrumplingSound(db, x, timeline, seed, 0, out);
    return out;
  };
  const double g = straight.direct.gain;
  // Constrained: the (0, 0) cell's only clip.
  const auto clac = play(0.05, 0.0, 1.0, 1);
  EXPECT_NEAR(clac[10], g * db.cells()[0].clips[0][10], 1e-9);
  // Twice the amplitude, twice the sound.
  const auto loud = play(0.05, 0.0, 2.0, 1);
  EXPECT_NEAR(loud[10], 2.0 * clac[10], 1e-9);
  // The (2.5, 5) cell has two variants: over seeds both are drawn.
  int first = 0, second = 0;
  for (std::uint64_t seed = 0; seed < 40; ++seed) {
    const auto flap = play(0.025, 0.05, 1.0, seed);
    if (std::abs(flap[10] - g * db.cells()[1].clips[0][10]) < 1e-9) ++first;
    if (std::abs(flap[10] - g * db.cells()[1].clips[1][10]) < 1e-9) ++second;
  }
  EXPECT_EQ(first + second, 40);
  EXPECT_GT(first, 5);
  EXPECT_GT(second, 5);
  const Timeline other(44100, 24.0, 24);
  std::vector<float> out;
  EXPECT_THROW(addCrumplingSound(db, e, other, 1, 0, out), std::invalid_argument);
}
