#pragma once
// The sheet models a shot runs behind one interface (docs/ARCHITECTURE.md
// "Sheet models"): the elastic model (a FEM on a fixed or cut mesh) and the
// crumpling model (paper Sec. 3-6: the coarse FEM S_P interleaved with the
// developable geometric layer S_G). The shot runner advances, tears,
// records and checkpoints a SheetModel without knowing which one it holds.
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "crumple/cache/pcache_structure.hpp"
#include "crumple/core/state_io.hpp"
#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/sim/elastic_sheet.hpp"
#include "crumple/sim/material.hpp"
#include "crumple/tear/tearing.hpp"

namespace crumple::paper {
struct ProjectionInput;  // crumple/paper/hybrid_sheet.hpp
}  // namespace crumple::paper

namespace crumple::model {

class HandleRig;

// What every model of one shot is built with; fixed for the shot.
struct ModelContext {
  sim::Material material;
  sim::SimParams sim;
  sim::ContactOptions contacts;  // its colliders outlive every model of the shot
  bool contactsOn = false;       // colliders or self-contact: the contact stage runs
  double fps = 24.0;             // animation frames per second
  int substeps = 1;              // per frame
  std::uint64_t seed = 0;
  // The scene's sheet at the elastic model's resolution (a torn crumpling
  // model's sheet is handed over onto it, docs/TEARING.md).
  std::function<mesh::SheetMesh()> elasticMesh;
  // The scene's [tear] parameters, as the elastic model runs them.
  tear::TearingParams tearing;
  // The crumpling model: called with every isometry projection's input
  // (paper Table III, the bench).
  std::function<void(const paper::ProjectionInput&)> projectionProbe;
};

// The crumpling model's structure changes of one frame: the cache's STRC
// record (paper Sec. 5-6), defined once with its codec.
using StructureChanges = cache::StructureChanges;

// What one frame's advance did: the run summary's counters.
struct FrameStats {
  long newtonIterations = 0;
  long halvings = 0;
  long substeps = 0;
  int newtonRetried = 0;       // steps taken again with more Newton iterations
  int selfContactDropped = 0;  // steps that went on without self-contact
  double contactMs = 0.0;      // collider work (timing only)
  double selfContactMs = 0.0;  // self-contact work (timing only)
  double airMs = 0.0;          // the air's terms in the elastic step (timing only)
  long selfContactSteps = 0;
  std::vector<std::pair<const char*, double>> stageMs;  // the frame's stages, in order
  // The crumpling model's (paper::HybridStepStats); absent for the elastic model.
  long elasticRetries = 0;
  long strainLimitRuns = 0, strainLimitCarried = 0;
  long elasticHeldStill = 0;
  double lag = 0.0;  // the largest handle lag of the frame (m)
  int lagVertex = -1;
  std::optional<std::vector<std::pair<int, double>>> handleLags;  // (vertex, lag)
  std::optional<StructureChanges> structure;
};

// The developable structure of the current mesh (paper Fig. 2), in the
// mesh's vertex indices: empty for the elastic model.
struct SheetStructure {
  std::vector<int> singularVertices;
  std::vector<int> junctionVertices;
  std::vector<std::array<int, 2>> rulings;
  // Which rulings are whose: region by region, in `rulings`' order, every
  // region with rulings (paper Sec. 3.2, R_C), with its apex (-1: none).
  struct RegionRulings {
    int region = -1;
    int apex = -1;
    int count = 0;
  };
  std::vector<RegionRulings> regions;
};

// A frame's tearing as a model takes it (thesis 3.3): the tear stage found
// the advances and cut `sheet` (the model's mesh); the model goes on with
// the cut sheet, or hands over to another model.
struct TearCut {
  int frame = 0;
  double t = 0.0;  // the frame's time (s)
  const tear::TearFrameResult& result;
  mesh::SheetMesh& sheet;                       // the mesh the tear stage cut
  tear::Tearing& tearing;                       // the tears so far
  const std::vector<tear::TearEvent>& earlier;  // every advance of earlier frames
};
struct TearOutcome {
  std::vector<tear::TearEvent> events;              // the frame's advances as the model took them
  std::unique_ptr<class SheetModel> replacement;    // a hand-over: the model from now on
  std::optional<tear::Tearing> replacementTearing;  // and its tears
  std::vector<std::string> notes;
  int geometricCuts = 0;     // advances cut in the crumpling model's S_G
  int regionsFlattened = 0;  // curved regions those cuts turned flat
};

class SheetModel {
 public:
  virtual ~SheetModel() = default;
  SheetModel() = default;
  SheetModel(const SheetModel&) = delete;
  SheetModel& operator=(const SheetModel&) = delete;

  // True for the crumpling model (the summary's "crumpling_model", the
  // checkpoint's model tag).
  virtual bool crumpling() const = 0;
  // Advances frame `frame` from frame - 1 (its substeps). Throws
  // NumericalError naming the frame and stage.
  virtual FrameStats advance(int frame, const sim::PinFunction& pins) = 0;
  // The sheet now: topology, pattern, regions and positions.
  virtual const mesh::SheetMesh& mesh() const = 0;
  virtual SheetStructure structure() const = 0;
  // How many singular vertices the model tracks (all of them, and those
  // inside the sheet); none for a model without a developable structure.
  virtual std::optional<std::pair<int, int>> singularCounts() const = 0;
  // What the sheet touches at the end of the frame.
  virtual const std::vector<sim::ContactSample>& contacts() const = 0;
  // The elastic step's sheet (its membrane forces drive the tears).
  virtual const sim::ElasticSheet& elastic() const = 0;

  // Tearing: the parameters the model runs the scene's [tear] with, the
  // mesh a frame's tear stage tests (positions the elastic step's), its
  // junction vertices (candidates too) and how near a tear's lips lie.
  virtual tear::TearingParams tearingParams(const tear::TearingParams& scene) const = 0;
  virtual mesh::SheetMesh tearMesh() const = 0;
  virtual std::vector<int> junctionVertices() const = 0;
  virtual double lipTolerance() const = 0;
  // True when the model rebuilds its mesh as it goes (the tears are bound
  // to it again every frame).
  virtual bool remeshes() const = 0;
  virtual TearOutcome cut(TearCut& cut) = 0;

  // Checkpoint (docs/CHECKPOINT.md): everything the next frames depend on.
  virtual void saveState(StateWriter& out) const = 0;
  virtual void restoreState(StateReader& in) = 0;
};

}  // namespace crumple::model
