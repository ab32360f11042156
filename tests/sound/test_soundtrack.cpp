// A shot's soundtrack from its events (thesis Algorithm 4, 4.3.4, 4.4):
// sync, stereo, the table, friction without clicks, tearing that follows the
// tip's speed, and the database at 44.1 kHz.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "crumple/sound/database.hpp"
#include "crumple/sound/soundtrack.hpp"
#include "sound_db_fixture.hpp"

using namespace crumple;
using namespace crumple::sound;

namespace {

Resonator disk(double ruling, double border, const Vec3& centre, double area = 0.01) {
  Resonator r;
  r.ruling = ruling;
  r.border = border;
  r.area = area;
  r.centre = centre;
  r.normal = Vec3::UnitY();
  r.radius = std::sqrt(area / std::numbers::pi);
  return r;
}

SoundEvent crumpling(double amplitude, const Resonator& r) {
  SoundEvent e;
  e.kind = EventKind::Crumpling;
  e.amplitude = amplitude;
  e.position = r.centre;
  e.resonators = {r};
  return e;
}

std::vector<FrameEvents> silentFrames(int n, const Vec3& listener = Vec3(0.0, 0.5, 1.0)) {
  std::vector<FrameEvents> frames(static_cast<std::size_t>(n));
  for (auto& f : frames) f.listener = listener;
  return frames;
}

double rms(const std::vector<float>& x, std::size_t from, std::size_t to) {
  double s = 0.0;
  for (std::size_t i = from; i < to; ++i) s += static_cast<double>(x[i]) * x[i];
  return std::sqrt(s / static_cast<double>(to - from));
}

struct Fixture {
  crumple::testing::DatabaseScratch scratch;
  SoundDatabase db;
  Fixture() {
    crumple::testing::writeDatabase(scratch.dir);
    db = SoundDatabase::load(scratch.dir);
  }
};

}  // namespace

// The sync acceptance through the whole mix: an event at frame 37
// of a 24 fps shot starts within 1 ms of 37 / 24 s, and the soundtrack lasts
// exactly 48 / 24 s.
TEST(Soundtrack, AnEventAtAFrameStartsAtItsTimeAndTheShotKeepsItsLength) {
  const Fixture f;
  const Timeline timeline(48000, 24.0, 48);
  auto frames = silentFrames(48);
  frames[37].events.push_back(crumpling(2e-3, disk(0.025, 0.05, Vec3(0.0, 0.02, 0.0))));
  SoundtrackSettings settings;
  settings.channels = 1;
  SoundtrackStats stats;
  const Audio audio = renderSoundtrack(f.db, timeline, frames, settings, &stats);
  ASSERT_EQ(audio.channels.size(), 1u);
  EXPECT_EQ(audio.sampleCount(), 96000u);
  EXPECT_EQ(stats.crumplingClips, 1);
  const auto& x = audio.channels[0];
  double peak = 0.0;
  for (float v : x) peak = std::max(peak, static_cast<double>(std::abs(v)));
  ASSERT_GT(peak, 0.0);
  std::size_t first = 0;
  while (std::abs(x[first]) < 0.05 * peak) ++first;
  EXPECT_NEAR(static_cast<double>(first) / 48000.0, 37.0 / 24.0, 1e-3);
  // Silent before it.
  EXPECT_EQ(rms(x, 0, 70000), 0.0);
}

// Stereo: a source on the listener's right is louder in the right ear; mono
// is one channel. The level falls with distance (1 / R).
TEST(Soundtrack, StereoPutsASourceOnItsSide) {
  const Fixture f;
  const Timeline timeline(48000, 24.0, 12);
  auto frames = silentFrames(12, Vec3::Zero());
  for (auto& fr : frames) fr.right = Vec3::UnitX();
  Resonator r = disk(0.1, 0.1, Vec3(1.0, 0.0, 0.0));
  r.normal = Vec3(-1.0, 0.0, 0.0);  // facing the listener
  frames[2].events.push_back(crumpling(1e-3, r));
  const Audio stereo = renderSoundtrack(f.db, timeline, frames, {});
  ASSERT_EQ(stereo.channels.size(), 2u);
  const double left = rms(stereo.channels[0], 0, stereo.sampleCount());
  const double right = rms(stereo.channels[1], 0, stereo.sampleCount());
  EXPECT_GT(right, 1.1 * left);
  // The right ear is 0.91 m away, the left 1.09 m: the ratio of 1 / R.
  EXPECT_NEAR(right / left, 1.09 / 0.91, 0.02);
  SoundtrackSettings mono;
  mono.channels = 1;
  EXPECT_EQ(renderSoundtrack(f.db, timeline, frames, mono).channels.size(), 1u);
  mono.channels = 3;
  EXPECT_THROW(renderSoundtrack(f.db, timeline, frames, mono), std::invalid_argument);
}

// Friction through the mix: a steady slide is continuous noise, with no
// click where blocks join (the acceptance: the largest
// sample-to-sample step within 4 standard deviations of the steps), and
// none before it starts.
TEST(Soundtrack, SteadyFrictionIsNoiseWithoutClicks) {
  const Fixture f;
  const Timeline timeline(48000, 24.0, 48);
  auto frames = silentFrames(48);
  for (int i = 12; i < 48; ++i) {
    SoundEvent e;
    e.kind = EventKind::Friction;
    e.amplitude = 0.1;
    e.resonators = {disk(0.1, 0.1, Vec3(0.0, 0.05, 0.0))};
    frames[static_cast<std::size_t>(i)].events.push_back(e);
  }
  SoundtrackSettings settings;
  settings.channels = 1;
  SoundtrackStats stats;
  const Audio audio = renderSoundtrack(f.db, timeline, frames, settings, &stats);
  EXPECT_GT(stats.frictionBlocks, 0);
  const auto& x = audio.channels[0];
  // Silent until friction starts (frame 11 fades it in towards frame 12).
  EXPECT_EQ(rms(x, 0, static_cast<std::size_t>(timeline.frameStart(10))), 0.0);
  // The steady stretch: frames 16 to 46.
  const auto from = static_cast<std::size_t>(timeline.frameStart(16));
  const auto to = static_cast<std::size_t>(timeline.frameStart(46));
  // Steps at the joins (every hop of M / 2 = 32 samples, where a click
  // would be) against all the stretch's steps. (Over all ~60 000 steps of
  // Gaussian noise the largest is ~sqrt(2 ln N) = 4.7 sd by chance alone.)
  const std::size_t hop = static_cast<std::size_t>(f.db.fftSize() / 2);
  double mean = 0.0, var = 0.0, atJoins = 0.0;
  const double n = static_cast<double>(to - from - 1);
  for (std::size_t i = from + 1; i < to; ++i) mean += (x[i] - x[i - 1]) / n;
  for (std::size_t i = from + 1; i < to; ++i) {
    const double step = x[i] - x[i - 1] - mean;
    var += step * step / n;
    if (i % hop == 0) atJoins = std::max(atJoins, std::abs(step));
  }
  ASSERT_GT(var, 0.0);
  EXPECT_LT(atJoins, 4.0 * std::sqrt(var));
  // Steady: the level of each frame within 20 % of the stretch's.
  const double whole = rms(x, from, to);
  for (int fr = 16; fr < 46; fr += 5) {
    const double level = rms(x, static_cast<std::size_t>(timeline.frameStart(fr)),
                             static_cast<std::size_t>(timeline.frameStart(fr + 1)));
    EXPECT_NEAR(level, whole, 0.2 * whole) << "frame " << fr;
  }
}

// The table's image: a friction source low over the table sounds different
// from one high above it (the comb's notches move), through the whole mix.
TEST(Soundtrack, TheTableColoursASourceByItsHeight) {
  const Fixture f;
  const Timeline timeline(48000, 24.0, 24);
  const auto at = [&](double height, bool table) {
    auto frames = silentFrames(24, Vec3(0.0, 0.3, 0.5));
    for (auto& fr : frames) {
      SoundEvent e;
      e.kind = EventKind::Friction;
      e.amplitude = 0.1;
      e.resonators = {disk(0.1, 0.1, Vec3(0.0, height, 0.0))};
      fr.events.push_back(e);
    }
    SoundtrackSettings s;
    s.channels = 1;
    if (table) s.table = ReflectingPlane{};
    const Audio a = renderSoundtrack(f.db, timeline, frames, s);
    return rms(a.channels[0], 4800, 43200);
  };
  // The table's own effect (the level with it over the level without it)
  // changes with the height: the image's interference.
  const double low = at(0.01, true) / at(0.01, false);
  const double high = at(0.08, true) / at(0.08, false);
  std::printf("[ measure ] table gain: %.3f at 1 cm, %.3f at 8 cm\n", low, high);
  EXPECT_GT(std::abs(low - high), 0.1);
}

// Tearing (4.4.1): a tear advancing faster is louder and crackles more.
TEST(Soundtrack, AFasterTearIsLouderAndCrackles) {
  const Fixture f;
  const Timeline timeline(48000, 24.0, 48);
  const auto tearAt = [&](double speed) {
    auto frames = silentFrames(48, Vec3(0.0, 0.0, 0.5));
    for (int i = 10; i < 40; ++i) {
      SoundEvent e;
      e.kind = EventKind::Tearing;
      e.tear = 0;
      e.amplitude = speed;
      e.duration = 1.0 / 24.0;
      e.normal = Vec3::UnitZ();
      frames[static_cast<std::size_t>(i)].events.push_back(e);
    }
    SoundtrackSettings s;
    s.channels = 1;
    return renderSoundtrack(f.db, timeline, frames, s).channels[0];
  };
  const auto slow = tearAt(0.02);
  const auto fast = tearAt(0.08);
  const auto from = static_cast<std::size_t>(timeline.frameStart(12));
  const auto to = static_cast<std::size_t>(timeline.frameStart(38));
  EXPECT_GT(rms(fast, from, to), 2.0 * rms(slow, from, to));
  EXPECT_EQ(rms(slow, 0, static_cast<std::size_t>(timeline.frameStart(8))), 0.0);
}

// 44.1 kHz: the database resampled, a 1 kHz clip still 1 kHz.
TEST(Soundtrack, TheDatabaseResamplesTo441kHz) {
  const Fixture f;
  const SoundDatabase low = f.db.resampledTo(44100);
  EXPECT_EQ(low.sampleRate(), 44100);
  const auto& clip48 = f.db.cells()[1].clips[0];  // 1 kHz
  const auto& clip44 = low.cells()[1].clips[0];
  EXPECT_NEAR(static_cast<double>(clip44.size()), clip48.size() * 44100.0 / 48000.0, 1.0);
  // Zero crossings per second stay 2000 (1 kHz).
  int crossings = 0;
  for (std::size_t i = 1; i < clip44.size() / 2; ++i)
    crossings += (clip44[i - 1] < 0.0f) != (clip44[i] < 0.0f);
  EXPECT_NEAR(crossings / (static_cast<double>(clip44.size() / 2) / 44100.0), 2000.0, 100.0);
  EXPECT_EQ(low.cells()[0].spectra[0].size(), f.db.cells()[0].spectra[0].size());
  EXPECT_THROW((void)f.db.resampledTo(22050), std::invalid_argument);
  const Timeline timeline(44100, 24.0, 24);
  auto frames = silentFrames(24);
  frames[5].events.push_back(crumpling(1e-3, disk(0.025, 0.05, Vec3(0.0, 0.02, 0.0))));
  EXPECT_THROW(renderSoundtrack(f.db, timeline, frames, {}), std::invalid_argument);
  EXPECT_EQ(renderSoundtrack(low, timeline, frames, {}).sampleCount(), 44100u);
}
