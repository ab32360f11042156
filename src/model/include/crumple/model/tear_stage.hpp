#pragma once
// The tearing stage of a frame (thesis 3.3, Fig. 3.14), after the model's
// advance: candidates tested with the step's membrane forces, the sheet cut
// where E_r >= E_f and the model going on with the cut sheet (or handing it
// over to another model), and the tear textures baked again when the mesh
// they refer to changed (thesis 3.3.4).
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "crumple/core/state_io.hpp"
#include "crumple/model/handle_rig.hpp"
#include "crumple/model/sheet_model.hpp"
#include "crumple/tear/tear_atlas.hpp"
#include "crumple/tear/tearing.hpp"

namespace crumple::model {

// What a frame's tearing did.
struct TearFrame {
  std::vector<tear::TearEvent> events;  // the frame's tip advances
  std::vector<std::string> notes;
  int geometricCuts = 0;     // advances cut in the crumpling model's S_G
  int regionsFlattened = 0;  // curved regions those cuts turned flat
  bool handedOver = false;   // the model was replaced
  // The tear textures of the current mesh, when baked again this frame.
  std::optional<tear::TearAtlas> atlas;
  double bakeMs = 0.0;
};

class TearStage {
 public:
  // The tears of `model`'s sheet, as the model runs the context's [tear].
  TearStage(const SheetModel& model, std::shared_ptr<const ModelContext> context);

  // Frame `frame` at time t: may replace `model` (a hand-over). `earlier`:
  // every advance of the frames before. Throws NumericalError naming the
  // frame and stage ("tear", "tear handover", "tear atlas").
  TearFrame run(int frame, double t, std::unique_ptr<SheetModel>& model, const HandleRig& rig,
                const std::vector<tear::TearEvent>& earlier);

  const tear::Tearing& tearing() const { return *tearing_; }

  // Checkpoint: the tears, and (separately) the mesh the last baked atlas
  // refers to. restoreState makes the tears again on `model`'s sheet.
  void saveState(StateWriter& out) const { tearing_->saveState(out); }
  void restoreState(StateReader& in, const SheetModel& model);
  void saveBaked(StateWriter& out) const;
  void restoreBaked(StateReader& in);

 private:
  std::shared_ptr<const ModelContext> context_;
  std::optional<tear::Tearing> tearing_;
  mesh::SheetMesh baked_;  // the triangles and pattern of the last baked atlas
};

}  // namespace crumple::model
