#pragma once
// A shot's sheet set up from its scene: the mesh, the model the scene asks
// for ([model] type) and the handle rig bound to it; and a model's state in
// a checkpoint. The one place that chooses a SheetModel implementation.
#include <memory>

#include "crumple/core/state_io.hpp"
#include "crumple/io/animation.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/model/handle_rig.hpp"
#include "crumple/model/sheet_model.hpp"

namespace crumple::model {

// The elastic model's mesh of the scene's [sheet]: a rectangle or outline
// meshed at max_edge, or the animation file's flat pattern_mesh. Throws
// InputError naming the scene file.
mesh::SheetMesh buildSheet(const io::SceneSpec& scene, const io::AnimationScene* animation);

// The model of a shot and the rig holding it, bound at time t0 (the first
// frame): the rig's pins moved onto their nodes.
struct ShotSheet {
  std::shared_ptr<const ModelContext> context;
  std::unique_ptr<HandleRig> rig;
  std::unique_ptr<SheetModel> model;
};
// `context`'s material, sim, contacts, fps, substeps, seed and tearing are
// the shot's; its elasticMesh is set here. `scene` and `animation` outlive
// the models. Throws InputError for a scene its model cannot run.
ShotSheet setUpSheet(const io::SceneSpec& scene, const io::AnimationScene* animation,
                     ModelContext context, double t0);

// The model in a checkpoint: which model, then its state. restoreModel
// restores into `model`, or replaces it by the model the checkpoint holds (a
// crumpling model handed over to the elastic model); throws
// CorruptDataError for a state of a model the scene cannot have.
void saveModel(StateWriter& out, const SheetModel& model);
void restoreModel(StateReader& in, std::unique_ptr<SheetModel>& model,
                  const std::shared_ptr<const ModelContext>& context, HandleRig& rig);

}  // namespace crumple::model
