// Scene-level tests of the air (docs/AIR.md) on its samples: a level sheet
// falls at the quasi-steady terminal speed and at least three times slower
// than without air; a strip on the tumbling side of Andersen, Pesavento &
// Wang's phase diagram tumbles and glides, a sheet on the fluttering side
// swings without turning over; a sheet on a desk stays put below the wind
// at which drag beats friction and slides above it, and the sample's gust
// carries it off the desk onto the floor; and a gusty shot is byte-identical
// on one and two threads.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/cache/pcache_contacts.hpp"
#include "crumple/cache/pcache_sound.hpp"
#include "crumple/pipeline/inspect.hpp"
#include "sample_shot.hpp"

using namespace crumple;
using namespace crumple::testing;  // the shared helpers (test_util.hpp)

namespace {

// The sheet's flight, frame by frame, up to and with the first frame
// touching a collider.
struct Flight {
  std::vector<double> time;
  std::vector<Vec3> centroid, normal;
  int landed = -1;  // index of the first frame touching a collider, -1: never
};

Flight flightOf(const std::string& cachePath) {
  const cache::CacheReader reader(cachePath);
  Flight f;
  for (std::size_t k = 0; k < reader.frameCount(); ++k) {
    const cache::FrameRecord frame = reader.readFrame(k);
    const pipeline::FrameMetrics m = pipeline::measureFrame(frame);
    f.time.push_back(frame.time);
    f.centroid.push_back(m.centroid);
    f.normal.push_back(m.meanNormal);
    if (const auto touching = cache::decodeContacts(frame.extensions)) {
      bool collider = false;
      for (const auto& c : *touching) collider = collider || c.collider != cache::kSelfContact;
      if (collider) {
        f.landed = static_cast<int>(k);
        break;
      }
    }
  }
  return f;
}

// When the centroid comes down to `height` (s): the parabola through the
// last three frames before the landing one (exact for a constant
// acceleration), carried on past the last of them; the landing frame itself
// is not used, the table stopped the sheet somewhere in its interval.
double timeAtHeight(const Flight& f, double height) {
  const auto k = static_cast<std::size_t>(f.landed) - 1;
  const double t0 = f.time[k - 2], t1 = f.time[k - 1], t2 = f.time[k];
  const double y0 = f.centroid[k - 2].y(), y1 = f.centroid[k - 1].y(), y2 = f.centroid[k].y();
  // y(s) = y2 + b s + c s^2 with s = t - t2.
  const double s0 = t0 - t2, s1 = t1 - t2;
  const double d0 = (y0 - y2) / s0, d1 = (y1 - y2) / s1;
  const double c = (d0 - d1) / (s0 - s1), b = d0 - c * s0;
  // The first s > 0 with y(s) = height (b < 0: coming down).
  const double disc = b * b - 4.0 * c * (y2 - height);
  const double s = std::abs(c) < 1e-12 ? (height - y2) / b : (-b - std::sqrt(disc)) / (2.0 * c);
  return t2 + s;
}

}  // namespace

TEST(AirSamples, FallFlatReachesTheTerminalSpeedAndFallsThreeTimesSlower) {
  TempDir dir;
  const io::SceneSpec scene = io::loadScene(sourcePath("samples/fall-flat/scene.toml"));
  ASSERT_TRUE(scene.sim.air.has_value());
  const std::string cachePath = simulateSample("fall-flat", dir);
  const Flight air = flightOf(cachePath);
  ASSERT_GE(air.landed, 0) << "the sheet lands within the shot";
  // The summary says the air ran and what it cost.
  const std::string summary = readFile(fs::path(cachePath).parent_path() / "summary.json");
  EXPECT_NE(summary.find("\"air\":true"), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"air\":{\"ms_per_frame\":"), std::string::npos) << summary;
  // Mean descent speed over the last 0.5 s of the fall (the frames before it lands).
  const std::size_t k1 = static_cast<std::size_t>(air.landed) - 1;
  std::size_t k0 = 0;
  while (k0 + 1 < k1 && air.time[k0] < air.time[k1] - 0.5) ++k0;
  const double descent =
      (air.centroid[k0].y() - air.centroid[k1].y()) / (air.time[k1] - air.time[k0]);
  const sim::AirParams& a = *scene.sim.air;
  const double terminal =
      std::sqrt(2.0 * scene.paper.material.arealDensity() * 9.81 / (a.density * a.dragNormal));
  // The same sheet in a vacuum: no [air], and no mass damping either (the
  // stand-in for air drag a scene without [air] runs).
  const std::string vacuumPath = simulateSample("fall-flat", dir, -1, [](io::SceneSpec& s) {
    s.sim.air.reset();
    s.sim.massDamping = 0.0;
    s.name = "fall-flat-vacuum";
  });
  const Flight vacuum = flightOf(vacuumPath);
  EXPECT_NE(readFile(fs::path(vacuumPath).parent_path() / "summary.json").find("\"air\":false"),
            std::string::npos);
  ASSERT_GE(vacuum.landed, 1);
  // Down to 5 mm above the table (the last frame is the one touching it).
  const double drop = air.centroid.front().y() - 0.005;
  const double tAir = timeAtHeight(air, 0.005), tVacuum = timeAtHeight(vacuum, 0.005);
  // The speed it comes down at: over the last frame before it touches.
  const auto landingSpeed = [](const Flight& f) {
    const auto k = static_cast<std::size_t>(f.landed) - 1;
    return (f.centroid[k - 1].y() - f.centroid[k].y()) / (f.time[k] - f.time[k - 1]);
  };
  const double vAir = landingSpeed(air), vVacuum = landingSpeed(vacuum);
  std::printf(
      "[ measure ] fall-flat: descent %.4f m/s over the last 0.5 s (terminal %.4f, %+.1f %%); "
      "%.2f m in %.3f s, %.3f s in a vacuum (%.2f times longer); lands at %.3f m/s, %.3f m/s in "
      "a vacuum (%.2f times slower)\n",
      descent, terminal, 100.0 * (descent / terminal - 1.0), drop, tAir, tVacuum, tAir / tVacuum,
      vAir, vVacuum, vVacuum / vAir);
  EXPECT_NEAR(descent, terminal, 0.15 * terminal);
  EXPECT_GE(tAir / tVacuum, 3.0);
  EXPECT_GE(vVacuum / vAir, 3.0);
}

namespace {

// The mean normal's angle about the z axis (the strip's long axis),
// unwrapped from frame to frame (rad).
std::vector<double> turning(const Flight& f) {
  std::vector<double> out;
  double total = 0.0, last = 0.0;
  for (std::size_t k = 0; k < f.normal.size(); ++k) {
    const double a = std::atan2(f.normal[k].y(), f.normal[k].x());
    if (k > 0) total += std::remainder(a - last, 2.0 * std::numbers::pi);
    last = a;
    out.push_back(total);
  }
  return out;
}

// The largest rotation in one direction without turning back (rad): frames
// may pause (a change under 1 degree against the direction) but not reverse.
double longestMonotonicTurn(const std::vector<double>& angle) {
  const double slack = std::numbers::pi / 180.0;
  double best = 0.0;
  for (const double sign : {1.0, -1.0}) {
    std::size_t start = 0;
    double peak = 0.0;
    for (std::size_t k = 1; k < angle.size(); ++k) {
      const double reached = sign * (angle[k] - angle[start]);
      if (reached < peak - slack) {  // turned back: start again from here
        start = k;
        peak = 0.0;
        continue;
      }
      peak = std::max(peak, reached);
      best = std::max(best, peak);
    }
  }
  return best;
}

}  // namespace

TEST(AirSamples, FallStripTumblesAndGlidesSideways) {
  TempDir dir;
  const Flight f = flightOf(simulateSample("fall-strip", dir));
  ASSERT_GE(f.landed, 0) << "the strip lands within the shot";
  const double turn = longestMonotonicTurn(turning(f));
  const double drift = std::abs(f.centroid.back().x() - f.centroid.front().x());
  std::printf(
      "[ measure ] fall-strip: turns %.2f times one way without turning back, drifts %.3f m in "
      "%.2f s\n",
      turn / (2.0 * std::numbers::pi), drift, f.time.back());
  EXPECT_GT(turn, 2.0 * std::numbers::pi);
  EXPECT_GT(drift, 0.20) << "more than the strip's length";
}

TEST(AirSamples, FallFlutterSwingsWithoutTurningOver) {
  TempDir dir;
  const std::string cachePath = simulateSample("fall-flutter", dir);
  const Flight f = flightOf(cachePath);
  ASSERT_GE(f.landed, 0) << "the sheet lands within the shot";
  double tilt = 0.0;
  for (const Vec3& n : f.normal)
    tilt = std::max(tilt, std::acos(std::clamp(n.y(), -1.0, 1.0)) * 180.0 / std::numbers::pi);
  // Reversals of the lateral motion (centroid velocity along x, ignoring
  // drifts under 1 cm/s).
  int reversals = 0;
  double lastSign = 0.0;
  for (std::size_t k = 1; k < f.time.size(); ++k) {
    const double vx = (f.centroid[k].x() - f.centroid[k - 1].x()) / (f.time[k] - f.time[k - 1]);
    if (std::abs(vx) < 0.01) continue;
    const double sign = vx > 0.0 ? 1.0 : -1.0;
    if (lastSign != 0.0 && sign != lastSign) ++reversals;
    lastSign = sign;
  }
  // Its sound: the flaps of the sheet flexing as it swings, in the air, and
  // the clac and slide of its landing.
  const cache::CacheReader reader(cachePath);
  ASSERT_TRUE(cache::decodeSoundSetup(reader.header().extensions).has_value()) << "[sound]";
  int flaps = 0, landing = 0;
  for (std::size_t k = 0; k < reader.frameCount(); ++k) {
    const auto events = cache::decodeSoundEvents(reader.readFrame(k).extensions);
    if (!events) continue;  // a frame without events
    for (const auto& e : *events) {
      if (static_cast<int>(k) < f.landed && e.kind == sound::EventKind::Crumpling) ++flaps;
      if (static_cast<int>(k) >= f.landed) ++landing;
    }
  }
  std::printf(
      "[ measure ] fall-flutter: largest tilt %.1f deg, %d lateral reversals in %.2f s; %d "
      "crumpling events in the air, %d from the landing on\n",
      tilt, reversals, f.time.back(), flaps, landing);
  EXPECT_LT(tilt, 90.0);
  EXPECT_GE(reversals, 2);
  EXPECT_GE(flaps, reversals);
  EXPECT_GT(landing, 0);
}

namespace {

// desk-draught with a steady wind along +x of `speed` (m/s) after a 0.25 s
// ramp and no gusts: how far the sheet moved in 1 s (m).
double deskSlide(const TempDir& dir, double speed, const std::string& name) {
  const std::string cachePath = simulateSample("desk-draught", dir, 24, [&](io::SceneSpec& s) {
    s.sim.air->wind = {{0.0, Vec3::Zero()}, {0.25, Vec3(speed, 0.0, 0.0)}};
    s.sim.air->gusts.speed = 0.0;
    s.name = name;
  });
  const cache::CacheReader reader(cachePath);
  const Vec3 first = pipeline::measureFrame(reader.readFrame(0)).centroid;
  const Vec3 last = pipeline::measureFrame(reader.readFrame(reader.frameCount() - 1)).centroid;
  return (last - first).norm();
}

}  // namespace

TEST(AirSamples, ASheetOnADeskSlidesOnlyAboveTheWindWhereDragBeatsFriction) {
  TempDir dir;
  const io::SceneSpec scene = io::loadScene(sourcePath("samples/desk-draught/scene.toml"));
  const sim::AirParams& a = *scene.sim.air;
  const double mu = scene.friction.at("wood");
  // Quasi-steady: 1/2 rho C_D(0) A w^2 = mu m g (the air flows along the desk).
  const double threshold = std::sqrt(2.0 * mu * scene.paper.material.arealDensity() * 9.81 /
                                     (a.density * a.dragTangential));
  const double below = deskSlide(dir, 0.8 * threshold, "below");
  const double above = deskSlide(dir, 1.2 * threshold, "above");
  std::printf(
      "[ measure ] desk-draught: quasi-steady threshold %.3f m/s; at 0.8 x the sheet moves %.2e m "
      "in 1 s, at 1.2 x %.3f m\n",
      threshold, below, above);
  EXPECT_LT(below, 1e-3);
  EXPECT_GT(above, 0.02);
}

TEST(AirSamples, AGustyShotIsByteIdenticalOnOneAndTwoThreads) {
  TempDir dir;
  const auto caches =
      cachesOnOneAndTwoThreads(sourcePath("samples/desk-draught") + " --frames 0-30", dir);
  EXPECT_FALSE(caches[0].empty());
  EXPECT_TRUE(caches[0] == caches[1]) << "byte-identical on 1 and 2 threads";
}

// The sample's gust slides the sheet to the desk's edge and carries it off,
// creasing it (the crumpling model); it lands on the floor beyond the desk.
// In free flight the crossing guard keeps the rigid part of a step that would
// pass the creased sheet through itself, so the sheet never stands still in
// the air (docs/CRUMPLING.md "A crossing that stops the whole sheet").
TEST(AirSamples, AGustCarriesTheSheetOffTheDeskOntoTheFloor) {
  TempDir dir;
  const io::SceneSpec scene =
      io::loadScene(io::resolveScenePath(sourcePath("samples/desk-draught")));
  pipeline::ShotOptions options;
  options.outDir = (dir / "desk-draught").string();
  options.render = false;
  options.log = nullptr;
  options.interactive = 0;
  const pipeline::ShotReport shot = pipeline::runShot(scene, options);
  const cache::CacheReader reader(shot.cachePath);
  const Vec3 end = pipeline::measureFrame(reader.readFrame(reader.frameCount() - 1)).centroid;
  const double deskEdge = 0.6, deskTop = 0.75;  // the sample's desk (m)
  std::printf(
      "[ measure ] desk-draught: the sheet ends %.2f m beyond the desk's edge, %.3f m above the "
      "floor; %ld elastic steps held still\n",
      end.x() - deskEdge, end.y(), shot.elasticHeldStill);
  EXPECT_EQ(shot.elasticHeldStill, 0);
  EXPECT_GT(end.x() - deskEdge, 0.5);
  EXPECT_LT(end.y(), 0.05 * deskTop);
}
