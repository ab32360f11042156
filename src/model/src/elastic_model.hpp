#pragma once
// The elastic model (docs/ELASTIC.md): a FEM sheet on a fixed mesh, cut
// where it tears (thesis 3.3). Private to the model module.
#include <memory>
#include <optional>
#include <vector>

#include "crumple/model/handle_rig.hpp"
#include "crumple/model/sheet_model.hpp"

namespace crumple::model {

class ElasticModel final : public SheetModel {
 public:
  // The sheet `mesh` (positions where it starts) held by `rig`. A torn
  // crumpling-model sheet handed over keeps its singular vertices (in the
  // cache's frames): `singular`.
  ElasticModel(mesh::SheetMesh mesh, std::shared_ptr<const ModelContext> context, HandleRig& rig,
               std::vector<int> singular = {});

  bool crumpling() const override { return false; }
  FrameStats advance(int frame, const sim::PinFunction& pins) override;
  const mesh::SheetMesh& mesh() const override { return mesh_; }
  SheetStructure structure() const override { return {singular_, {}, {}, {}}; }
  std::optional<std::pair<int, int>> singularCounts() const override { return std::nullopt; }
  const std::vector<sim::ContactSample>& contacts() const override;
  const sim::ElasticSheet& elastic() const override { return sheet_; }

  tear::TearingParams tearingParams(const tear::TearingParams& scene) const override {
    return scene;
  }
  mesh::SheetMesh tearMesh() const override { return mesh_; }
  std::vector<int> junctionVertices() const override { return {}; }
  double lipTolerance() const override { return 0.0; }
  bool remeshes() const override { return false; }
  TearOutcome cut(TearCut& cut) override;

  void saveState(StateWriter& out) const override;
  void restoreState(StateReader& in) override;
  // The model a checkpoint holds, its FEM built once on the saved mesh (a
  // crumpling-model sheet handed over to the elastic model).
  static std::unique_ptr<ElasticModel> restored(StateReader& in,
                                                std::shared_ptr<const ModelContext> context,
                                                HandleRig& rig);

  // A sheet just handed over settles: `steps` implicit steps of dt ending
  // at t, its pins where they are, then takes `velocities`.
  void settle(double t, int steps, double dt, const std::vector<Vec3>& velocities);

 private:
  // Contacts and the fingers' grips on the sheet `sheet_`.
  void attach();
  // The state after the saved mesh, on a sheet built on it.
  void restoreOnMesh(StateReader& in);

  std::shared_ptr<const ModelContext> context_;
  HandleRig& rig_;
  mesh::SheetMesh mesh_;
  sim::ElasticSheet sheet_;
  std::vector<int> singular_;
  // The contacts of a frame whose sheet was rebuilt by a cut (vertex
  // indices survive a cut), until the next advance.
  std::optional<std::vector<sim::ContactSample>> carried_;
};

}  // namespace crumple::model
