// Scene-level tests of tearing on its samples (tear-straight,
// tear-curved, tear-notch): where each tear starts, the path it takes in the
// pattern against Roman's hyperbolae (thesis 3.3.1, 3.3.5), and the torn
// sheet itself: the lips' vertices part in 3D, no triangle crosses a lip,
// the edge lengths stay near the pattern's, the detail path is longer than
// the tips' polyline; and a run that repeats byte for byte.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>

#include "crumple/cache/pcache.hpp"
#include "crumple/cache/pcache_tear.hpp"
#include "crumple/exporters/mesh_export.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/mesh/developable.hpp"
#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/pipeline/inspect.hpp"
#include "crumple/pipeline/refine.hpp"
#include "crumple/pipeline/shot.hpp"
#include "crumple/pipeline/tear_measures.hpp"
#include "crumple/tear/candidates.hpp"
#include "crumple/tear/detail_path.hpp"
#include "test_util.hpp"

using namespace crumple;
using namespace crumple::testing;  // the shared helpers (test_util.hpp)

namespace {

struct TearShot {
  io::SceneSpec scene;
  pipeline::ShotReport report;
  cache::FrameRecord last;  // the final frame
};

// Simulates `scene` into `out` quietly, without rendering.
pipeline::ShotReport simulate(const io::SceneSpec& scene, const std::string& out) {
  pipeline::ShotOptions options;
  options.outDir = out;
  options.render = false;
  options.log = nullptr;  // quiet
  options.interactive = 0;
  pipeline::ShotReport report = pipeline::runShot(scene, options);
  return report;
}

// Runs the sample to its last frame, or to `lastFrame` when that is given.
TearShot runTearSample(const std::string& sample, const TempDir& dir, const std::string& sub = "",
                       int lastFrame = -1) {
  TearShot shot;
  shot.scene = io::loadScene(io::resolveScenePath(sourcePath("samples/" + sample)));
  if (lastFrame >= 0) shot.scene.frameEnd = lastFrame;
  shot.report = simulate(shot.scene, (dir / (sample + sub)).string());
  const cache::CacheReader reader(shot.report.cachePath);
  shot.last = reader.readFrame(reader.frameCount() - 1);
  return shot;
}

// The torn sheet at the last frame: every lip vertex has a twin at the same
// pattern point; returns the largest 3D distance between twins, checks that
// the mesh is valid (no triangle crosses a lip: the cut edges are boundary
// edges of simple loops) and the edge lengths.
double lipOpening(const TearShot& shot) {
  mesh::SheetMesh m;
  m.pattern = shot.last.pattern;
  m.positions = shot.last.positions;
  m.triangles = shot.last.triangles;
  m.regionOfTriangle.assign(m.triangles.size(), 0);
  m.regionTypes = {mesh::RegionType::Flat};
  EXPECT_EQ(mesh::validate(m), "");
  EXPECT_NO_THROW((void)tear::boundaryLoops(m)) << "the outline and the lips are simple loops";
  // Twins: boundary vertices at one pattern point (the elastic model's cuts)
  // or across the crumpling model's slit (a few kerfs of 10 um apart).
  std::vector<int> boundary;
  for (const auto& loop : tear::boundaryLoops(m))
    boundary.insert(boundary.end(), loop.begin(), loop.end());
  double opening = 0.0;
  for (std::size_t i = 0; i < boundary.size(); ++i)
    for (std::size_t j = i + 1; j < boundary.size(); ++j) {
      const auto a = static_cast<std::size_t>(boundary[i]),
                 b = static_cast<std::size_t>(boundary[j]);
      if ((m.pattern[a] - m.pattern[b]).norm() <= 1.2e-4)
        opening = std::max(opening, (m.positions[a] - m.positions[b]).norm());
    }
  return opening;
}

// How much longer the detail paths are than the straight segments between
// successive tips.
double detailRatio(const pipeline::ShotReport& r) {
  double detail = 0.0, straight = 0.0;
  for (const auto& s : r.tearSegments) {
    detail += tear::pathLength(s.detail);
    straight += (s.detail.back() - s.detail.front()).norm();
  }
  return straight > 0.0 ? detail / straight : 0.0;
}

void expectTornSheet(const TearShot& shot, const char* name) {
  const auto& r = shot.report;
  EXPECT_TRUE(r.tearingOn);
  EXPECT_EQ(r.error, "");
  const double opening = lipOpening(shot);
  const double ratio = detailRatio(r);
  std::printf(
      "[ measure ] %s: %zu tear(s), first at frame %d, %zu advances; lips %.2f mm apart; "
      "c_mean max %.4f %%; detail path %.3f x the tips' segments; tearing %.2f ms/frame\n",
      name, r.tearStartKinds.size(), r.firstTearFrame, r.tearAdvances.size(), 1e3 * opening,
      100.0 * r.maxCMean, ratio, r.tearMs / std::max(1, r.framesSimulated - 1));
  EXPECT_GT(opening, 2e-3) << "the lips part in 3D";
  EXPECT_LE(r.maxCMean, 0.005) << "c_mean stays <= 0.5 %";
  EXPECT_GE(ratio, 1.15) << "the detail path is fibrous";
}

TEST(TearSamples, TearStraightRunsDownTheBisectorOfItsPullingPoints) {
  const TempDir dir;
  const TearShot shot = runTearSample("tear-straight", dir);
  const auto& r = shot.report;
  ASSERT_EQ(r.tearStartKinds.size(), 1u);
  EXPECT_EQ(r.tearStartKinds[0], tear::CandidateKind::InwardCorner) << "at the notch's root";
  const std::vector<Vec2> tips = pipeline::tearTips(r);
  ASSERT_GE(tips.size(), 4u);
  EXPECT_GT((tips.back() - tips.front()).norm(), 0.015) << "the tear runs at least 1.5 cm";
  // The pulling points are mirror images about u = 6 cm: the tear's path,
  // its successive tips s_t, follows that line within 2 % of the sheet
  // width (12 cm). The mesh's cut (snapped to the mesh) and the detail path
  // (the fibers' walk) are reported beside it.
  const double u = pipeline::kTearStraightBisectorU;
  const double worst = pipeline::straightTearDeviation(tips, u);
  double cut = 0.0, detail = 0.0;
  for (const auto& s : r.tearSegments) {
    cut = std::max(cut, pipeline::straightTearDeviation(s.cut, u));
    detail = std::max(detail, pipeline::straightTearDeviation(s.detail, u));
  }
  std::printf(
      "[ measure ] tear-straight: the tips stray at most %.2f mm (%.2f %% of the width) "
      "from the pulling points' bisector over %.1f cm; the mesh's cut %.2f mm, the detail "
      "path %.2f mm\n",
      1e3 * worst, 100.0 * worst / 0.12, 100.0 * (tips.back() - tips.front()).norm(), 1e3 * cut,
      1e3 * detail);
  EXPECT_LE(worst, 0.02 * 0.12);
  expectTornSheet(shot, "tear-straight");
}

TEST(TearSamples, TearCurvedBisectsTheDirectionsToItsPullingPoints) {
  const TempDir dir;
  const TearShot shot = runTearSample("tear-curved", dir);
  const auto& r = shot.report;
  ASSERT_EQ(r.tearStartKinds.size(), 1u);
  EXPECT_EQ(r.tearStartKinds[0], tear::CandidateKind::InwardCorner);
  // Roman: the tangent at every point c of the path bisects the angle
  // between the directions from the pulling points A and B to c. Sampled at
  // 0.5 mm steps along the tips' polyline.
  const std::vector<Vec2> tips = pipeline::tearTips(r);
  ASSERT_GE(tips.size(), 3u);
  const std::vector<double> errors =
      pipeline::hyperbolaAngleErrors(tips, pipeline::kTearCurvedPullA, pipeline::kTearCurvedPullB);
  std::vector<double> sorted = errors;
  std::sort(sorted.begin(), sorted.end());
  const auto at = [&](double q) {
    return sorted[static_cast<std::size_t>(q * (sorted.size() - 1))];
  };
  std::size_t within = 0;
  for (double e : errors) within += e <= 10.0 ? 1 : 0;
  std::printf(
      "[ measure ] tear-curved: %zu samples over %.1f cm; angle between the path and the "
      "bisector: median %.1f, 75 %% %.1f, 90 %% %.1f, max %.1f deg; %.0f %% within 10 deg\n",
      errors.size(), 100.0 * tear::pathLength(tips), at(0.5), at(0.75), at(0.9), sorted.back(),
      100.0 * static_cast<double>(within) / errors.size());
  EXPECT_GE(static_cast<double>(within), 0.9 * static_cast<double>(errors.size()));
  expectTornSheet(shot, "tear-curved");
}

TEST(TearSamples, TearNotchStartsAtTheInwardCornerAndRepeatsByteForByte) {
  const TempDir dir;
  const TearShot shot = runTearSample("tear-notch", dir);
  const auto& r = shot.report;
  ASSERT_GE(r.tearStartKinds.size(), 1u);
  EXPECT_EQ(r.tearStartKinds[0], tear::CandidateKind::InwardCorner);
  ASSERT_FALSE(r.tearAdvances.empty());
  EXPECT_LT((r.tearAdvances.front().event.from - Vec2(0.05, 0.05)).norm(), 1e-9)
      << "the L's inward corner";
  expectTornSheet(shot, "tear-notch");
  // Determinism: the same scene again gives the same cache, byte for byte.
  const TearShot again = runTearSample("tear-notch", dir, "-again");
  EXPECT_EQ(crumple::testing::readFile(r.cachePath),
            crumple::testing::readFile(again.report.cachePath));
}

TEST(TearSamples, ASceneWithoutTearNeverTears) {
  // tear-notch with [tear] enabled = false: the same pulls, no tear, no tearing stage.
  const TempDir dir;
  io::SceneSpec scene = io::loadScene(io::resolveScenePath(sourcePath("samples/tear-notch")));
  scene.tearEnabled = false;
  scene.frameEnd = 30;
  const auto r = simulate(scene, (dir / "off").string());
  EXPECT_FALSE(r.tearingOn);
  EXPECT_TRUE(r.tearAdvances.empty());
  EXPECT_EQ(r.stages.count("tear"), 0u);
  const cache::CacheReader reader(r.cachePath);
  EXPECT_EQ(reader.readFrame(reader.frameCount() - 1).triangles.size(),
            reader.readFrame(0).triangles.size());
}

}  // namespace

namespace {

TEST(TearSamples, TearCylinderStartsAtAJunctionPoint) {
  // Thesis Fig. 3.26: flattening one border of the crumpling model's half
  // tube tears it at a junction point between its curved region and a flat
  // one; the tear cuts S_G and the crumpling model goes on with the torn
  // sheet (docs/TEARING.md "The crumpling model torn").
  const TempDir dir;
  // Frames 0-53: the tear (frame 40), the torn crumpling model and two
  // frames of the elastic model after the hand-over (frame 52). The rest of
  // the shot runs the elastic model on the 5 mm mesh (2.6 s per frame) and
  // tests nothing more.
  const TearShot shot = runTearSample("tear-cylinder", dir, "", 53);
  const auto& r = shot.report;
  EXPECT_EQ(r.error, "");
  ASSERT_FALSE(r.tearStartKinds.empty());
  EXPECT_EQ(r.tearStartKinds[0], tear::CandidateKind::Junction);
  EXPECT_GE(r.firstTearFrame, 36) << "the flattening (from 1.5 s) tears it, not the wrap";
  EXPECT_GE(r.tearGeometricCuts, 3) << "the tear advances in S_G";
  const int crumplingUntil = r.tearHandoverFrame >= 0 ? r.tearHandoverFrame : 1 << 30;
  EXPECT_GT(crumplingUntil, r.firstTearFrame + 2) << "the crumpling model goes on torn";
  const double opening = lipOpening(shot);
  // c_mean before the tear, of the torn crumpling model, and after a hand-over.
  const cache::CacheReader reader(r.cachePath);
  double before = 0.0, torn = 0.0, elastic = 0.0;
  for (std::size_t k = 0; k < reader.frameCount(); ++k) {
    const auto f = reader.readFrame(k);
    double& worst = f.frame < r.firstTearFrame ? before : f.frame < crumplingUntil ? torn : elastic;
    worst = std::max(worst, pipeline::measureFrame(f).cMean);
  }
  std::printf(
      "[ measure ] tear-cylinder: %zu tear(s) (the first from a junction at frame %d), "
      "%zu advances, %d of them in S_G (%d curved regions flattened), hand-over at frame %d; "
      "lips %.2f mm apart; c_mean at most %.3f %% before the tear, %.3f %% torn in the "
      "crumpling model, %.3f %% after the hand-over; detail path %.3f x the tips' segments\n",
      r.tearStartKinds.size(), r.firstTearFrame, r.tearAdvances.size(), r.tearGeometricCuts,
      r.tearRegionsFlattened, r.tearHandoverFrame, 1e3 * opening, 100.0 * before, 100.0 * torn,
      100.0 * elastic, detailRatio(r));
  EXPECT_GT(opening, 2e-3);
  EXPECT_GE(detailRatio(r), 1.15);
  // Refined (pipeline/refine.hpp, what render and export draw), the torn
  // frames keep their tear textures texel for texel: the patched triangles
  // stay, their patches follow them, and the atlas fits the refined mesh.
  int tornRefined = 0;
  for (std::size_t k = 0; k < reader.frameCount(); ++k) {
    const auto f = reader.readFrame(k);
    const auto tears = cache::decodeTearAtlas(f.extensions);
    if (!tears) continue;
    cache::FrameRecord refined = f;
    const auto stats = pipeline::refineFrame(refined, mesh::RefineOptions{});
    if (!stats || stats->refinedRuns == 0) continue;
    ++tornRefined;
    const auto moved = cache::decodeTearAtlas(refined.extensions);
    ASSERT_TRUE(moved.has_value());
    EXPECT_EQ(mesh::validate(*moved, pipeline::sheetOfFrame(refined)), "") << f.frame;
    EXPECT_EQ(moved->mask, tears->mask) << f.frame;
    ASSERT_EQ(moved->patches.size(), tears->patches.size());
    for (std::size_t p = 0; p < tears->patches.size(); ++p) {
      const auto& before = f.triangles[tears->patches[p].triangle];
      const auto& after = refined.triangles[moved->patches[p].triangle];
      EXPECT_EQ(after, before) << "the patched triangle stays, frame " << f.frame;
      EXPECT_EQ(moved->patches[p].polygon, tears->patches[p].polygon);
    }
    const exporters::UvMapping uv = exporters::uvMappingOf(f.pattern, "the frame");
    EXPECT_EQ(exporters::tearTexture(refined, uv)->pixels, exporters::tearTexture(f, uv)->pixels)
        << f.frame;
    EXPECT_LE(mesh::meanLengthError(pipeline::sheetOfFrame(refined)),
              pipeline::measureFrame(f).cMean + 1e-4)
        << f.frame;
  }
  std::printf("[ measure ] tear-cylinder: %d torn frames with curved regions refined\n",
              tornRefined);
  EXPECT_GT(tornRefined, 0) << "the test bites";
  // The untorn crumpling model itself reaches 3.2 % in this shot (the
  // fingers stretch the flattened border): a bound against blow-up.
  EXPECT_LE(torn, 0.04);
}

TEST(TearSamples, TheCrumplingModelTearsAtAJunctionAndGoesOnCrumpling) {
  // cylinder-fold with [tear]: as its tube bends, the sheet tears at a
  // junction point of S_G (thesis 3.3.2); the tear cuts S_G and the
  // crumpling model runs on to the end with the torn sheet: its frames keep
  // rulings and junction points, and the rulings keep changing. Without
  // self-contact: the 0.25 cm elastic reference of this motion never
  // touches itself, while the crumpling model's S_P folds onto itself after
  // the bend; where the crossing guard then stops it, the jammed sheet tears
  // into 5 pieces and goes on as the elastic model from frame 73
  // (docs/CRUMPLING.md "The crossing guard"). This test is about the tear's
  // path through S_G, at 2 animation steps per frame: at the sample's 3 the
  // sheet tears five times, a tip reaches the outline and the torn-apart
  // sheet is handed over to the elastic model at frame 79 (docs/TEARING.md,
  // "A sheet torn apart").
  const TempDir dir;
  io::SceneSpec scene = io::loadScene(io::resolveScenePath(sourcePath("samples/cylinder-fold")));
  scene.substeps = 2;
  scene.tearEnabled = true;
  scene.contact.self = io::ContactSpec::Self::Off;
  const auto r = simulate(scene, (dir / "cylinder").string());
  EXPECT_EQ(r.error, "");
  ASSERT_FALSE(r.tearStartKinds.empty());
  EXPECT_EQ(r.tearStartKinds[0], tear::CandidateKind::Junction);
  EXPECT_GT(r.firstTearFrame, 0);
  EXPECT_EQ(r.tearHandoverFrame, -1) << "the torn sheet stays the crumpling model's";
  EXPECT_EQ(r.tearGeometricCuts, static_cast<int>(r.tearAdvances.size()));
  const cache::CacheReader reader(r.cachePath);
  double torn = 0.0;  // c_mean over the frames after the tear
  int tornFrames = 0, withRulings = 0, rulingChanges = 0;
  std::vector<std::array<int, 2>> lastRulings;
  for (std::size_t k = 0; k < reader.frameCount(); ++k) {
    const auto f = reader.readFrame(k);
    EXPECT_EQ(cache::decodeTearAtlas(f.extensions).has_value(), f.frame >= r.firstTearFrame)
        << "frame " << f.frame;
    if (f.frame < r.firstTearFrame) continue;
    torn = std::max(torn, pipeline::measureFrame(f).cMean);
    ++tornFrames;
    if (!f.rulings.empty() && !f.junctionVertices.empty()) ++withRulings;
    if (f.frame > r.firstTearFrame && f.rulings != lastRulings) ++rulingChanges;
    lastRulings = f.rulings;
  }
  std::printf(
      "[ measure ] cylinder-fold with [tear]: tore at frame %d at a junction, %zu "
      "advances in S_G, ran on to frame %d as the crumpling model; %d of its %d torn frames "
      "have rulings and junctions, the rulings changed in %d; c_mean of the torn frames at "
      "most %.4f %%\n",
      r.firstTearFrame, r.tearAdvances.size(), reader.readFrame(reader.frameCount() - 1).frame,
      withRulings, tornFrames, rulingChanges, 100.0 * torn);
  EXPECT_EQ(withRulings, tornFrames);
  EXPECT_GT(rulingChanges, 0) << "the geometric step goes on after the tear";
  EXPECT_LE(torn, 0.005);
}

}  // namespace

namespace {

TEST(TearSamples, TearNotchIsByteIdenticalOnOneAndTwoThreads) {
  // Frames 0-30 hold the first tear (frame 16) and four tip advances.
  const TempDir dir;
  std::string caches[2];
  for (const int threads : {1, 2}) {
    const std::string out = (dir / std::to_string(threads)).string();
    const auto r = crumple::testing::runCrumple("simulate " + sourcePath("samples/tear-notch") +
                                                " --frames 0-30 --threads " +
                                                std::to_string(threads) + " --out " + out);
    ASSERT_EQ(r.status, 0) << r.output;
    caches[threads - 1] = crumple::testing::readFile(out + "/cache.pcache");
    const cache::CacheReader reader(out + "/cache.pcache");
    EXPECT_GT(reader.readFrame(reader.frameCount() - 1).tearCount, 0u) << "it tore";
  }
  EXPECT_FALSE(caches[0].empty());
  EXPECT_TRUE(caches[0] == caches[1]) << "byte-identical on 1 and 2 threads";
}

}  // namespace
