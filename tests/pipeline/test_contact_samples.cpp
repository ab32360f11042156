// Scene-level tests of contacts on its samples (slide-on-table,
// press-on-sphere, fold-over): at every frame no free vertex lies deeper
// than 10 % of the paper's thickness inside a collider or inside the sheet,
// measured from the cache with the colliders at the frame's time; the sheet
// touches what it should (the cache's contact set); the run summary's
// figures agree with the frames.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "crumple/cache/pcache.hpp"
#include "crumple/cache/pcache_contacts.hpp"
#include "crumple/core/error.hpp"
#include "crumple/io/animation.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/pipeline/contacts.hpp"
#include "crumple/pipeline/shot.hpp"
#include "test_util.hpp"

using namespace crumple;
using namespace crumple::testing;  // the shared helpers (test_util.hpp)

namespace {

struct ContactShot {
  double worstDepth = 0.0;  // thicknesses, over every frame
  int worstFrame = -1;
  long framesTouchingColliders = 0;
  long framesTouchingItself = 0;
  double fastestSlide = 0.0;  // m/s
  std::size_t frames = 0;
  pipeline::ShotReport report;
};

ContactShot runContactSample(const std::string& sample, const TempDir& dir) {
  const io::SceneSpec scene = io::loadScene(io::resolveScenePath(sourcePath("samples/" + sample)));
  pipeline::ShotOptions options;
  options.outDir = (dir / sample).string();
  options.render = false;
  options.log = nullptr;  // quiet
  options.interactive = 0;
  ContactShot shot;
  shot.report = pipeline::runShot(scene, options);
  // Re-measure every cached frame against the colliders at its time.
  std::unique_ptr<io::AnimationScene> animation;
  if (!scene.animationFile.empty())
    animation = std::make_unique<io::AnimationScene>(io::AnimationScene::load(scene.animationFile));
  pipeline::SceneColliders colliders(scene, animation.get());
  const sim::ContactOptions contact = pipeline::contactOptionsOf(scene, colliders);
  const cache::CacheReader reader(shot.report.cachePath);
  EXPECT_TRUE(cache::decodeColliders(reader.header().extensions).has_value());
  for (std::size_t k = 0; k < reader.frameCount(); ++k) {
    const cache::FrameRecord f = reader.readFrame(k);
    colliders.moveTo(f.time);
    const double depth = pipeline::contactDepth(contact, f);
    if (depth > shot.worstDepth) {
      shot.worstDepth = depth;
      shot.worstFrame = f.frame;
    }
    if (const auto touching = cache::decodeContacts(f.extensions)) {
      bool collider = false, self = false;
      for (const auto& c : *touching) {
        EXPECT_LT(static_cast<std::size_t>(c.vertex), f.positions.size()) << "frame " << f.frame;
        (c.collider == cache::kSelfContact ? self : collider) = true;
        shot.fastestSlide = std::max(shot.fastestSlide, static_cast<double>(c.slideSpeed));
      }
      shot.framesTouchingColliders += collider ? 1 : 0;
      shot.framesTouchingItself += self ? 1 : 0;
    }
  }
  shot.frames = reader.frameCount();
  std::printf(
      "[ measure ] %s: %zu frames, deepest vertex %.4f thicknesses (frame %d); %ld frames "
      "on colliders, %ld on itself; fastest slide %.3f m/s; contacts %.2f + %.2f ms "
      "(colliders + self) of the step's, %.1f %%\n",
      sample.c_str(), shot.frames, shot.worstDepth, shot.worstFrame, shot.framesTouchingColliders,
      shot.framesTouchingItself, shot.fastestSlide, shot.report.contactMs,
      shot.report.selfContactMs, 100.0 * shot.report.contactShareOfStep());
  return shot;
}

void expectOutsideEverywhere(const ContactShot& shot) {
  EXPECT_EQ(shot.report.error, "");
  EXPECT_LE(shot.worstDepth, 0.1) << "deepest at frame " << shot.worstFrame;
  // The summary measured the same thing while simulating.
  EXPECT_NEAR(shot.report.maxContactDepth, shot.worstDepth, 1e-9);
}

}  // namespace

// Thesis Fig. 4.4: the front edge slides on the table toward the held back
// edge, then the back is released and the front pinched.
TEST(ContactSamples, SlideOnTableStaysOnTheTableAndSlides) {
  TempDir dir;
  const ContactShot shot = runContactSample("slide-on-table", dir);
  expectOutsideEverywhere(shot);
  EXPECT_GT(shot.framesTouchingColliders, static_cast<long>(shot.frames) / 2)
      << "the sheet lies on the table";
  EXPECT_GT(shot.fastestSlide, 0.01) << "and slides on it";
}

TEST(ContactSamples, PressOnSphereWrapsTheBallWithoutEnteringIt) {
  TempDir dir;
  const ContactShot shot = runContactSample("press-on-sphere", dir);
  expectOutsideEverywhere(shot);
  EXPECT_GT(shot.framesTouchingColliders, static_cast<long>(shot.frames) / 3);
}

TEST(ContactSamples, FoldOverLiesOnItselfWithoutPassingThrough) {
  TempDir dir;
  const ContactShot shot = runContactSample("fold-over", dir);
  expectOutsideEverywhere(shot);
  EXPECT_GT(shot.report.selfContactSteps, 0) << "self-contact ran";
  EXPECT_GT(shot.framesTouchingItself, 0) << "the flap lies on the sheet";
}

// Determinism with self-contact (FCL's broad phase, the pairs' order): the
// same cache on 1 and on 2 threads.
TEST(ContactSamples, FoldOverIsByteIdenticalOnOneAndTwoThreads) {
  TempDir dir;
  const auto caches = cachesOnOneAndTwoThreads(sourcePath("samples/fold-over"), dir);
  EXPECT_FALSE(caches[0].empty());
  EXPECT_TRUE(caches[0] == caches[1]) << "byte-identical on 1 and 2 threads";
}
