#pragma once
// The crumpling model (paper Sec. 3-6; docs/CRUMPLING.md): paper::HybridSheet
// behind the SheetModel interface, with its tears (thesis 3.3.3) and its
// hand-over to the elastic model when S_G cannot take a tear. Private to the
// model module.
#include <memory>
#include <vector>

#include "crumple/model/handle_rig.hpp"
#include "crumple/model/sheet_model.hpp"
#include "crumple/paper/hybrid_sheet.hpp"

namespace crumple::model {

class CrumplingModel final : public SheetModel {
 public:
  CrumplingModel(std::unique_ptr<paper::HybridSheet> sheet,
                 std::shared_ptr<const ModelContext> context);
  // Binds the handles at t0: the pinned vertices placed, the fingers' grips,
  // the tangent vertices chosen again on every S_P rebuild.
  void bind(HandleRig& rig, double t0);

  bool crumpling() const override { return true; }
  FrameStats advance(int frame, const sim::PinFunction& pins) override;
  const mesh::SheetMesh& mesh() const override { return sheet_->physical().mesh; }
  SheetStructure structure() const override;
  std::optional<std::pair<int, int>> singularCounts() const override {
    return std::pair{sheet_->singularVertexCount(), sheet_->interiorSingularVertexCount()};
  }
  const std::vector<sim::ContactSample>& contacts() const override { return sheet_->contacts(); }
  const sim::ElasticSheet& elastic() const override { return sheet_->elastic(); }

  tear::TearingParams tearingParams(const tear::TearingParams& scene) const override;
  mesh::SheetMesh tearMesh() const override;
  std::vector<int> junctionVertices() const override;
  double lipTolerance() const override;
  bool remeshes() const override { return true; }
  TearOutcome cut(TearCut& cut) override;

  void saveState(StateWriter& out) const override { sheet_->saveState(out); }
  void restoreState(StateReader& in) override;

 private:
  // S_G's singular vertices (S_P's first vertices are S_G's).
  std::vector<int> singularVertices() const;
  // A torn sheet S_G cannot take goes on as the elastic model (docs/TEARING.md).
  void handOver(TearCut& cut, TearOutcome& out);

  std::unique_ptr<paper::HybridSheet> sheet_;
  std::shared_ptr<const ModelContext> context_;
  HandleRig* rig_ = nullptr;
  // The singular vertices when the frame began (those of the last recorded
  // frame): a sheet handed over keeps them.
  std::vector<int> singularAtStart_;
};

}  // namespace crumple::model
