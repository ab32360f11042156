// The sheet models behind model::SheetModel (docs/ARCHITECTURE.md "Sheet
// models"): the scene picks the model, both advance, record their structure
// and come back from a saved state to the same bytes.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "../pipeline/test_util.hpp"
#include "crumple/core/error.hpp"
#include "crumple/core/state_io.hpp"
#include "crumple/io/animation.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/model/sheet_setup.hpp"
#include "crumple/model/tear_stage.hpp"

using namespace crumple;
using crumple::testing::sourcePath;

namespace {

// A bundled sample, its animation and the models' context as a shot builds it
// (no colliders, no self-contact).
struct Sample {
  io::SceneSpec scene;
  std::unique_ptr<io::AnimationScene> animation;
  explicit Sample(const std::string& name)
      : scene(io::loadScene(io::resolveScenePath(sourcePath("samples/" + name)))),
        animation(
            std::make_unique<io::AnimationScene>(io::AnimationScene::load(scene.animationFile))) {}
  model::ShotSheet setUp() const {
    model::ModelContext c;
    c.material = scene.paper.material;
    c.sim = scene.sim;
    c.sim.recoverFailedSteps = true;
    c.fps = scene.fps;
    c.substeps = scene.substeps;
    c.seed = scene.seed;
    c.tearing = scene.tearing;
    return model::setUpSheet(scene, animation.get(), c, scene.frameTime(scene.frameStart));
  }
};

sim::PinFunction pinsOf(const model::HandleRig& rig) {
  return [&rig](double t, std::vector<sim::Pin>& out) { rig.pins(t, out); };
}

TEST(SheetModel, TheSceneChoosesTheModel) {
  const Sample drape("drape");
  const model::ShotSheet elastic = drape.setUp();
  EXPECT_FALSE(elastic.model->crumpling());
  EXPECT_FALSE(elastic.model->singularCounts().has_value());
  EXPECT_TRUE(elastic.model->structure().rulings.empty());
  EXPECT_FALSE(elastic.model->remeshes());
  EXPECT_EQ(elastic.model->mesh().vertexCount(),
            model::buildSheet(drape.scene, nullptr).vertexCount());

  const Sample fold("cylinder-fold");
  const model::ShotSheet crumpling = fold.setUp();
  EXPECT_TRUE(crumpling.model->crumpling());
  EXPECT_TRUE(crumpling.model->remeshes());
  ASSERT_TRUE(crumpling.model->singularCounts().has_value());
  EXPECT_EQ(crumpling.model->singularCounts()->first, 0) << "a flat sheet has none yet";
  // Every handle holds a vertex of the model's mesh.
  for (const auto& h : crumpling.rig->handles()) {
    EXPECT_GE(h.vertex, 0);
    EXPECT_LT(static_cast<std::size_t>(h.vertex), crumpling.model->mesh().vertexCount());
  }
  // The crumpling model runs its tears with S_G's cut rules.
  const tear::TearingParams& scene = fold.scene.tearing;
  EXPECT_GT(crumpling.model->tearingParams(scene).minStartAngle, scene.minStartAngle);
  EXPECT_EQ(elastic.model->tearingParams(scene).minStartAngle, scene.minStartAngle);
}

// Both models advance a few frames; a state saved after frame 3 restores
// into a freshly set-up shot, and the frames after it come out the same to
// the bit.
TEST(SheetModel, ASavedStateGoesOnAsTheOriginal) {
  for (const char* name : {"drape", "cylinder-fold"}) {
    SCOPED_TRACE(name);
    const Sample sample(name);
    model::ShotSheet a = sample.setUp();
    const sim::PinFunction pinsA = pinsOf(*a.rig);
    long substeps = 0;
    for (int f = 1; f <= 3; ++f) substeps += a.model->advance(f, pinsA).substeps;
    EXPECT_EQ(substeps, 3L * sample.scene.substeps);
    StateWriter w;
    model::saveModel(w, *a.model);
    a.rig->saveState(w);
    for (int f = 4; f <= 5; ++f) (void)a.model->advance(f, pinsA);

    model::ShotSheet b = sample.setUp();
    StateReader in(w.data(), "test state");
    model::restoreModel(in, b.model, b.context, *b.rig);
    b.rig->restoreState(in);
    EXPECT_TRUE(in.atEnd());
    const sim::PinFunction pinsB = pinsOf(*b.rig);
    for (int f = 4; f <= 5; ++f) (void)b.model->advance(f, pinsB);
    EXPECT_EQ(a.model->mesh().positions, b.model->mesh().positions);
    EXPECT_EQ(a.model->mesh().triangles, b.model->mesh().triangles);
    EXPECT_EQ(a.model->structure().singularVertices, b.model->structure().singularVertices);
  }
}

// A crumpling model's state is refused by a scene that runs the elastic
// model; an elastic state (a crumpling sheet handed over to the elastic
// model) replaces a crumpling model.
TEST(SheetModel, AStateRestoresOnlyIntoAModelThatCanHoldIt) {
  const Sample fold("cylinder-fold");
  const model::ShotSheet crumpling = fold.setUp();
  StateWriter w;
  model::saveModel(w, *crumpling.model);
  const Sample drape("drape");
  model::ShotSheet elastic = drape.setUp();
  StateReader in(w.data(), "test state");
  EXPECT_THROW(model::restoreModel(in, elastic.model, elastic.context, *elastic.rig),
               CorruptDataError);

  StateWriter e;
  model::saveModel(e, *elastic.model);
  model::ShotSheet other = fold.setUp();
  StateReader back(e.data(), "test state");
  model::restoreModel(back, other.model, other.context, *other.rig);
  EXPECT_FALSE(other.model->crumpling());
  EXPECT_EQ(other.model->mesh().positions, elastic.model->mesh().positions);
}

}  // namespace
