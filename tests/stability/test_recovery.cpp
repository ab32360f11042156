// The stability fixes (docs/STABILITY.md "Fixes made for the
// suite") at unit level: the elastic step's recovery after a failure at every
// halving, and the handles held within the sheet's reach.
#include <gtest/gtest.h>

#include <cmath>

#include "../pipeline/test_util.hpp"
#include "crumple/core/error.hpp"
#include "crumple/io/animation.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/model/handle_rig.hpp"
#include "crumple/model/sheet_setup.hpp"
#include "crumple/pipeline/shot.hpp"
#include "crumple/sim/elastic_sheet.hpp"

using namespace crumple;
using crumple::testing::sourcePath;

namespace {

// A 21 x 29.7 cm sheet tilted by 0.3 rad about its top edge, held at its top
// corners: released, it swings, and its first step starts from a cold
// predictor.
struct Swing {
  mesh::SheetMesh mesh;
  sim::PinFunction pins;
};
Swing tiltedSheet() {
  Swing s;
  s.mesh = mesh::makeRectangleSheet(0.21, 0.297, 0.03);
  const Vec3 vAxis(0.0, std::cos(0.3), std::sin(0.3));
  mesh::placePattern(s.mesh, -0.297 * vAxis, Vec3::UnitX(), vAxis);
  const int a = mesh::nearestPatternVertex(s.mesh, Vec2(0.0, 0.297));
  const int b = mesh::nearestPatternVertex(s.mesh, Vec2(0.21, 0.297));
  const Vec3 pa = s.mesh.positions[static_cast<std::size_t>(a)];
  const Vec3 pb = s.mesh.positions[static_cast<std::size_t>(b)];
  s.pins = [=](double, std::vector<sim::Pin>& out) {
    out.push_back({a, pa});
    out.push_back({b, pb});
  };
  return s;
}

}  // namespace

// Newton needs more than 2 iterations from the cold predictor, so with a cap
// of 2 and no halving the step fails; the recovery takes it again with
// kRetryIterationFactor times the cap and it converges.
TEST(ElasticRecovery, AStepThatNeedsMoreNewtonIterationsIsTakenAgainWithThem) {
  const Swing s = tiltedSheet();
  sim::SimParams p;
  p.maxNewtonIterations = 2;
  p.maxHalvings = 0;
  // Without the recovery (the default of SimParams) the step fails.
  sim::ElasticSheet plain(s.mesh, sim::Material{}, p);
  EXPECT_THROW(plain.advance(0.0, 1.0 / 96.0, s.pins), NumericalError);
  p.recoverFailedSteps = true;  // as in a shot
  sim::ElasticSheet sheet(s.mesh, sim::Material{}, p);
  sim::StepStats stats;
  ASSERT_NO_THROW(stats = sheet.advance(0.0, 1.0 / 96.0, s.pins));
  EXPECT_EQ(stats.newtonRetried, 1);
  EXPECT_EQ(stats.selfContactDropped, 0);
  EXPECT_GT(stats.newtonIterations, p.maxNewtonIterations);
  for (const Vec3& x : sheet.positions()) EXPECT_TRUE(x.allFinite());
  // The same step with a cap it meets needs no recovery and gives the same
  // state to the Newton tolerance.
  sim::SimParams enough;
  sim::ElasticSheet reference(s.mesh, sim::Material{}, enough);
  EXPECT_EQ(reference.advance(0.0, 1.0 / 96.0, s.pins).newtonRetried, 0);
  double worst = 0.0;
  for (std::size_t i = 0; i < s.mesh.vertexCount(); ++i)
    worst = std::max(worst, (sheet.positions()[i] - reference.positions()[i]).norm());
  EXPECT_LT(worst, 1e-6);
}

// A step no recovery can save (a pin target that is not a number) still
// throws, names the attempts and restores the state.
TEST(ElasticRecovery, AHopelessStepStillThrowsNamingEveryAttempt) {
  const Swing s = tiltedSheet();
  sim::SimParams p;
  p.recoverFailedSteps = true;
  sim::ElasticSheet sheet(s.mesh, sim::Material{}, p);
  const sim::PinFunction nan = [&](double t, std::vector<sim::Pin>& out) {
    s.pins(t, out);
    out.front().position.x() = std::nan("");
  };
  try {
    sheet.advance(0.0, 1.0 / 96.0, nan);
    FAIL() << "expected NumericalError";
  } catch (const NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("with more Newton iterations: non-finite pin target"),
              std::string::npos)
        << e.what();
  }
  for (std::size_t i = 0; i < s.mesh.vertexCount(); ++i)
    EXPECT_EQ(sheet.positions()[i], s.mesh.positions[i]);
}

// tests/stability/scenes/beyond-reach: A holds still, B's node goes to 40 cm
// from it (at 1.0-1.5 s). B's pin stops on the reach, 10 cm x (1 +
// kReachSlack) from A's; A's stays on its node. A sheet that may tear is
// pulled as its nodes say.
TEST(HandleReach, TheMovingHandleStopsOnTheSheetsReachUnlessItMayTear) {
  io::SceneSpec scene =
      io::loadScene(io::resolveScenePath(sourcePath("tests/stability/scenes/beyond-reach")));
  const io::AnimationScene anim = io::AnimationScene::load(scene.animationFile);
  const mesh::SheetMesh sheet = model::buildSheet(scene, &anim);
  const double t0 = scene.frameStart / scene.fps;
  const double t = 1.25;
  const double reach = 0.10 * (1.0 + model::HandleRig::kReachSlack);
  {
    const model::HandleRig rig(scene, &anim, sheet, t0);
    std::vector<sim::Pin> pins;
    rig.pins(t, pins);
    ASSERT_EQ(pins.size(), 2u);
    EXPECT_EQ(pins[0].position, rig.target(0, t));
    EXPECT_NEAR((pins[1].position - pins[0].position).norm(), reach, 1e-12);
    EXPECT_NEAR((rig.target(1, t) - rig.target(0, t)).norm(), 0.40, 1e-6);
    EXPECT_EQ(rig.reachExcess(0, t), 0.0);
    EXPECT_NEAR(rig.reachExcess(1, t), 0.40 - reach, 1e-6);
    // Within reach (the first frame) the pins are the nodes.
    rig.pins(t0, pins);
    EXPECT_EQ(pins[1].position, rig.target(1, t0));
    EXPECT_EQ(rig.reachExcess(1, t0), 0.0);
  }
  scene.tearEnabled = true;
  const model::HandleRig tearing(scene, &anim, sheet, t0);
  std::vector<sim::Pin> pins;
  tearing.pins(t, pins);
  EXPECT_EQ(pins[1].position, tearing.target(1, t));
  EXPECT_EQ(tearing.reachExcess(1, t), 0.0);
}
