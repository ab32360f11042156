// Scene-level tests of the soundtrack on its samples: wiggle
// flaps, a crumpled sheet clacks, slide-on-table rubs while sliding and
// flaps when its back stands up, the friction's centroid rises as the sheet
// shrinks (A4 > A5 > A6), a faster tear is louder and crackles more, and
// `crumple sound` writes a WAV of exactly the shot's length with its
// spectrogram, byte for byte the same every time.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>

#include "crumple/cache/pcache.hpp"
#include "crumple/cache/pcache_sound.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/pipeline/shot.hpp"
#include "crumple/pipeline/sound.hpp"
#include "crumple/sound/database.hpp"
#include "crumple/sound/soundtrack.hpp"
#include "crumple/sound/spectrogram.hpp"
#include "crumple/sound/wav.hpp"
#include "sample_shot.hpp"
#include "test_util.hpp"

using namespace crumple;
using namespace crumple::testing;  // the shared helpers (test_util.hpp)
namespace fs = std::filesystem;

namespace {

struct CachedEvents {
  std::vector<int> frames;  // frame number per cached frame
  std::vector<std::vector<sound::SoundEvent>> events;
  double fps = 24.0;
};

CachedEvents readEvents(const std::string& cachePath) {
  const cache::CacheReader reader(cachePath);
  EXPECT_TRUE(cache::decodeSoundSetup(reader.header().extensions));
  CachedEvents out;
  out.fps = reader.header().fps;
  for (std::size_t i = 0; i < reader.frameCount(); ++i) {
    const auto frame = reader.readFrame(i);
    out.frames.push_back(frame.frame);
    out.events.push_back(
        cache::decodeSoundEvents(frame.extensions).value_or(std::vector<sound::SoundEvent>{}));
  }
  return out;
}

struct Census {
  int events = 0;
  int clac = 0, flap = 0;  // crumpling resonators
  double clacArea = 0.0, flapArea = 0.0;
};

Census crumplingCensus(const CachedEvents& c, int from = -1, int to = 1 << 30) {
  Census s;
  for (std::size_t i = 0; i < c.frames.size(); ++i) {
    if (c.frames[i] < from || c.frames[i] > to) continue;
    for (const auto& e : c.events[i]) {
      if (e.kind != sound::EventKind::Crumpling) continue;
      ++s.events;
      for (const auto& r : e.resonators) {
        if (r.border > 0.0) {
          ++s.flap;
          s.flapArea += e.amplitude * r.area;
        } else {
          ++s.clac;
          s.clacArea += e.amplitude * r.area;
        }
      }
    }
  }
  return s;
}

sound::SoundDatabase defaultDatabase() {
  return sound::SoundDatabase::load(sourcePath("assets/sound/default"));
}

// The power spectrum's centroid (Hz) of a mono signal, from Hann-windowed
// frames of 2048 samples.
double spectralCentroid(const std::vector<float>& x, int rate) {
  sound::Audio a;
  a.sampleRate = rate;
  a.channels = {x};
  sound::SpectrogramParams p;
  p.fftSize = 2048;
  p.height = 1024;  // one row per bin
  p.floorDb = -300.0;
  const auto levels = sound::spectrogramLevels(a, p);
  double num = 0.0, den = 0.0;
  for (const auto& column : levels)
    for (std::size_t k = 0; k < column.size(); ++k) {
      const double power = std::pow(10.0, column[k] / 10.0);
      num += power * (k + 0.5) * rate / 2048.0;
      den += power;
    }
  return den > 0.0 ? num / den : 0.0;
}

}  // namespace

// Thesis Figs. 4.21, 4.22 and 4.7: the wiggled sheet's crumpling events are
// flaps (its resonators reach the free, curved bottom border); the crumpled
// sheet's are mostly clacs (flat regions between folds and singular points,
// without a free border).
TEST(SoundSamples, WiggleFlapsAndACrumpledSheetClacs) {
  const TempDir dir;
  const CachedEvents wiggle = readEvents(simulateSample("wiggle", dir));
  // With its strain limit on (the default) the squeezed sheet stands still
  // from frame 32 while its handles lag (docs/CRUMPLING.md, "Strain limit")
  // and makes 2 crumpling events after 2 s; the census needs a sheet that
  // goes on crumpling, so this shot runs without the limit.
  const CachedEvents crumple = readEvents(simulateSample(
      "crumple", dir, -1, [](io::SceneSpec& s) { s.crumpling.maxEdgeStrain = 0.0; }));
  const Census w = crumplingCensus(wiggle);
  // The crumple sample while it crumples: from 1 s, when its corners fold
  // and its singular vertices multiply (3 -> 8 over frames 24-28). Without
  // the limit it then holds its shape: no event after frame 35.
  const Census c = crumplingCensus(crumple, 24);
  std::printf(
      "[ measure ] wiggle: %d crumpling events, %d flap / %d clac resonators; crumple (from 1 s): "
      "%d events, %d flap / %d clac resonators, clac share of amplitude x area %.2f\n",
      w.events, w.flap, w.clac, c.events, c.flap, c.clac, c.clacArea / (c.clacArea + c.flapArea));
  EXPECT_GE(w.events, 10);
  EXPECT_EQ(w.clac, 0);
  // The sheet flaps only while it is shaken (frames 12-72).
  for (std::size_t i = 0; i < wiggle.frames.size(); ++i)
    if (!wiggle.events[i].empty()) {
      EXPECT_GE(wiggle.frames[i], 12);
      EXPECT_LE(wiggle.frames[i], 80);
    }
  EXPECT_GE(c.events, 10);
  EXPECT_GT(c.clac, c.flap / 2);
  EXPECT_GT(c.clacArea, 0.5 * (c.clacArea + c.flapArea));
}

// Thesis Fig. 4.4: friction in every frame the front edge slides on the
// table faster than 2 cm/s (0.3-1.6 s), none while it holds (1.6-2.0 s), and
// flaps when the released back stands up (2.0-2.5 s, frames 48-60): a
// resonator with a long free border.
TEST(SoundSamples, SlideOnTableRubsWhileSlidingAndFlapsWhenTheBackStandsUp) {
  const TempDir dir;
  const std::string cachePath = simulateSample("slide-on-table", dir);
  const CachedEvents c = readEvents(cachePath);
  // The front-left handle's speed at every frame, from its track.
  const cache::CacheReader reader(cachePath);
  const auto& names = reader.header().handleNames;
  const auto front =
      static_cast<std::size_t>(std::find(names.begin(), names.end(), "front-left") - names.begin());
  ASSERT_LT(front, names.size());
  std::vector<double> speed(c.frames.size(), 0.0);
  for (std::size_t i = 1; i < c.frames.size(); ++i)
    speed[i] =
        (reader.readFrame(i).handleTargets[front] - reader.readFrame(i - 1).handleTargets[front])
            .norm() *
        c.fps;
  std::string timeline;
  int sliding = 0, slidingWithFriction = 0, holdFriction = 0, standFlaps = 0;
  double longestBorder = 0.0;
  for (std::size_t i = 0; i < c.frames.size(); ++i) {
    const int f = c.frames[i];
    int friction = 0, flaps = 0, clacs = 0;
    for (const auto& e : c.events[i]) {
      if (e.kind == sound::EventKind::Friction) ++friction;
      if (e.kind != sound::EventKind::Crumpling) continue;
      for (const auto& r : e.resonators) {
        (r.border > 0.0 ? flaps : clacs) += 1;
        if (f >= 48 && f <= 60) longestBorder = std::max(longestBorder, r.border);
      }
    }
    if (f < 48 && speed[i] > 0.02) {
      ++sliding;
      slidingWithFriction += friction > 0;
    }
    if (f >= 40 && f < 48) {
      EXPECT_LT(speed[i], 1e-3) << "frame " << f << " is not in the hold";
      holdFriction += friction;
    }
    if (f >= 48 && f <= 60) standFlaps += flaps;
    char line[96];
    std::snprintf(line, sizeof line, " %d:%s%s%s", f, friction ? "F" : "", flaps ? "f" : "",
                  clacs ? "c" : "");
    if (friction || flaps || clacs) timeline += line;
  }
  std::printf(
      "[ measure ] slide-on-table: friction in %d of the %d frames the front edge slides faster "
      "than 2 cm/s; events (F friction, f flap, c clac):%s\n",
      slidingWithFriction, sliding, timeline.c_str());
  EXPECT_GE(sliding, 15);
  EXPECT_EQ(slidingWithFriction, sliding);
  EXPECT_EQ(holdFriction, 0);
  EXPECT_GE(standFlaps, 5);
  // The standing back: a free border of about the sheet's width (21 cm).
  EXPECT_GT(longestBorder, 0.15);
}

// Thesis Fig. 4.16: sheets of A4, A5 and A6 bowed into an arch and slid on
// a table; the friction sound's spectral centroid rises as the sheet
// shrinks. The arches' resonators come from the event detector, their
// sound from the default database through the mix.
TEST(SoundSamples, FrictionCentroidRisesAsTheSheetShrinks) {
  const sound::SoundDatabase db = defaultDatabase();
  std::vector<double> centroids;
  for (const auto& [name, w, h] : {std::tuple{"A4", 0.297, 0.210}, std::tuple{"A5", 0.210, 0.148},
                                   std::tuple{"A6", 0.148, 0.105}}) {
    // Bowed along its length w into an arch of 120 degrees, both short
    // edges on the table (y = 0) and sliding at 5 cm/s.
    mesh::SheetMesh m = mesh::makeRectangleSheet(w, h, 0.005);
    const double angle = 2.0 * std::numbers::pi / 3.0, radius = w / angle;
    m.positions.clear();
    for (const Vec2& p : m.pattern) {
      const double a = (p.x() / w - 0.5) * angle;
      m.positions.emplace_back(radius * std::sin(a), radius * (std::cos(a) - std::cos(angle / 2)),
                               p.y());
    }
    sound::SheetFrame frame;
    frame.mesh = &m;
    frame.frameDuration = 1.0 / 24.0;
    for (std::size_t v = 0; v < m.vertexCount(); ++v)
      if (m.pattern[v].x() < 1e-9 || m.pattern[v].x() > w - 1e-9)
        frame.contacts.push_back({static_cast<int>(v), 0.05});
    sound::EventDetector detector;
    const auto events = detector.detect(frame);
    ASSERT_EQ(events.size(), 2u) << name;  // the two edges on the table
    for (const auto& e : events) {
      ASSERT_EQ(e.resonators.size(), 1u);
      // The arch between them: its long borders are free but for their
      // edges (5 mm) touching the table.
      EXPECT_NEAR(e.resonators[0].border, 2.0 * (w - 0.01), 0.01 * w) << name;
    }
    const sound::Timeline timeline(48000, 24.0, 48);
    std::vector<sound::FrameEvents> frames(48);
    for (auto& f : frames) {
      f.events = events;
      f.listener = Vec3(0.0, 0.3, 0.6);
    }
    sound::SoundtrackSettings settings;
    settings.channels = 1;
    settings.table = sound::ReflectingPlane{};
    const sound::Audio audio = sound::renderSoundtrack(db, timeline, frames, settings);
    centroids.push_back(spectralCentroid(audio.channels[0], 48000));
    std::printf("[ measure ] %s arch (l_r %.1f cm, l_c %.1f cm): friction centroid %.0f Hz\n", name,
                100.0 * events[0].resonators[0].ruling, 100.0 * events[0].resonators[0].border,
                centroids.back());
  }
  EXPECT_GT(centroids[1], centroids[0]);  // A5 above A4
  EXPECT_GT(centroids[2], centroids[1]);  // A6 above A5
}

// Thesis 4.4 and Fig. 4.23: the same tear made slowly (tear-slow, 4 s) and
// fast (tear-fast, 0.5 s). The tearing noise alone, in the thesis' 50 ms
// clips while the tear runs: the fast tear's is louder (amplitude follows
// the tip's speed) and crackles more (its pitch follows the speed too: more
// fibres break in each clip, and the largest bursts stand out more).
TEST(SoundSamples, AFasterTearIsLouderAndCracklesMore) {
  CRUMPLE_LONG_TEST();  // several minutes
  const TempDir dir;
  const sound::SoundDatabase db = defaultDatabase();
  struct Measure {
    double speed = 0.0, rms = 0.0, crest = 0.0;
  };
  std::map<std::string, Measure> m;
  for (const std::string sample : {"tear-slow", "tear-fast"}) {
    const CachedEvents c = readEvents(simulateSample(sample, dir));
    std::vector<sound::FrameEvents> frames(c.frames.size());
    double length = 0.0, time = 0.0;
    for (std::size_t i = 0; i < c.frames.size(); ++i) {
      frames[i].listener = Vec3(0.06, 0.065, 0.3);  // the samples' camera, 30 cm in front
      for (const auto& e : c.events[i])
        if (e.kind == sound::EventKind::Tearing) {
          frames[i].events.push_back(e);
          length += e.amplitude * e.duration;
          time += e.duration;
        }
    }
    ASSERT_GT(time, 0.0) << sample << " did not tear";
    const sound::Timeline timeline(48000, c.fps, static_cast<int>(c.frames.size()));
    sound::SoundtrackSettings settings;
    settings.channels = 1;
    const auto x = sound::renderSoundtrack(db, timeline, frames, settings).channels[0];
    // 50 ms clips where the tear sounds: their RMS and crest factors.
    std::vector<double> rms, crest;
    for (std::size_t start = 0; start + 2400 <= x.size(); start += 2400) {
      double sum = 0.0, peak = 0.0;
      for (std::size_t i = start; i < start + 2400; ++i) {
        sum += static_cast<double>(x[i]) * x[i];
        peak = std::max(peak, static_cast<double>(std::abs(x[i])));
      }
      if (sum == 0.0) continue;
      rms.push_back(std::sqrt(sum / 2400.0));
      crest.push_back(peak / rms.back());
    }
    ASSERT_GE(rms.size(), 3u);
    std::sort(rms.begin(), rms.end());
    std::sort(crest.begin(), crest.end());
    m[sample] = {length / time, rms[rms.size() / 2], crest[crest.size() / 2]};
    std::printf(
        "[ measure ] %s: mean tip speed %.4f m/s; over %zu clips of 50 ms, median RMS %.4g, "
        "median crest factor %.2f\n",
        sample.c_str(), m[sample].speed, rms.size(), m[sample].rms, m[sample].crest);
  }
  EXPECT_GT(m["tear-fast"].speed, 3.0 * m["tear-slow"].speed);
  EXPECT_GT(m["tear-fast"].rms, 2.0 * m["tear-slow"].rms);
  EXPECT_GT(m["tear-fast"].crest, m["tear-slow"].crest);
}

// `crumple sound`: the WAV lasts exactly frame_count / fps at either rate,
// in either format, with its spectrogram beside it; the same cache gives
// the same bytes; a cache simulated without [sound] is refused.
TEST(SoundSamples, CrumpleSoundWritesTheShotsSoundtrack) {
  const TempDir dir;
  const std::string cache = simulateSample("wiggle", dir);
  const auto a = runCrumple("sound " + cache + " --out " + (dir / "a.wav").string());
  ASSERT_EQ(a.status, 0) << a.output;
  EXPECT_NE(a.output.find("215 flap"), std::string::npos) << a.output;
  const sound::Audio wav = sound::readWav(dir / "a.wav");
  EXPECT_EQ(wav.sampleRate, 48000);
  EXPECT_EQ(wav.channels.size(), 2u);
  EXPECT_EQ(wav.sampleCount(), 182000u);  // 91 frames at 24 fps
  EXPECT_TRUE(fs::exists(dir / "a.png"));
  const auto b = runCrumple("sound " + cache + " --out " + (dir / "b.wav").string());
  ASSERT_EQ(b.status, 0) << b.output;
  EXPECT_EQ(readFile(dir / "a.wav"), readFile(dir / "b.wav"));
  EXPECT_EQ(readFile(dir / "a.png"), readFile(dir / "b.png"));
  const auto c = runCrumple("sound " + cache + " --rate 44100 --format float --channels 1 " +
                            "--no-spectrogram --out " + (dir / "c.wav").string());
  ASSERT_EQ(c.status, 0) << c.output;
  const sound::Audio low = sound::readWav(dir / "c.wav");
  EXPECT_EQ(low.sampleRate, 44100);
  EXPECT_EQ(low.channels.size(), 1u);
  EXPECT_EQ(low.sampleCount(), 167213u);  // 91 / 24 s at 44.1 kHz, to the nearest sample
  EXPECT_FALSE(fs::exists(dir / "c.png"));
  const auto events = runCrumple("sound " + cache + " --events");
  EXPECT_EQ(events.status, 0);
  EXPECT_NE(events.output.find(" crumpling "), std::string::npos);
  EXPECT_EQ(runCrumple("sound " + cache + " --rate 22050").status, 2);
  // A shot without [sound]: a clear refusal, exit status 2.
  const std::string silent = simulateSample("drape", dir);
  const auto refused = runCrumple("sound " + silent);
  EXPECT_EQ(refused.status, 2);
  EXPECT_NE(refused.output.find("[sound]"), std::string::npos) << refused.output;
}
