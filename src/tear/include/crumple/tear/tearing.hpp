#pragma once
// The tearing stage of a shot, frame by frame (thesis 3.3, Fig. 3.14): the
// frame's candidate tearing points are tested against the Griffith
// criterion with the forces of the elastic step; every tip that tears
// advances by V E_r along its propagation direction, and the strongest new
// candidate that tears starts a tear; the mesh is cut along each advance
// (cutAlong) and every advance is recorded with its detail path
// (TearSegment) for the baked tear textures.
#include <cstdint>
#include <string>
#include <vector>

#include "crumple/core/state_io.hpp"
#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/tear/cut.hpp"
#include "crumple/tear/detail_path.hpp"
#include "crumple/tear/fiber_texture.hpp"
#include "crumple/tear/params.hpp"
#include "crumple/tear/tear_segment.hpp"
#include "crumple/tear/tear_step.hpp"

namespace crumple::tear {

// One advance of one tear in a frame.
struct TearEvent {
  int tear = -1;
  bool started = false;                     // this advance started the tear
  CandidateKind kind = CandidateKind::Tip;  // the candidate it advanced from
  int vertex = -1;                          // that candidate's vertex
  double energyRelease = 0.0;               // E_r (N)
  double fractureEnergy = 0.0;              // E_f (N)
  Vec2 from = Vec2::Zero();                 // s_t (pattern, m)
  Vec2 to = Vec2::Zero();                   // s_{t+1} as the mesh took it
  bool separated = false;                   // the tear reached the boundary: it ends there
};

struct TearFrameResult {
  std::vector<CandidateTest> tests;  // every candidate of the frame
  std::vector<TearEvent> events;     // in the order the cuts were made
  std::size_t vertexCountBefore = 0;
  // One per vertex appended this frame, over the vertices before the frame.
  std::vector<VertexBlend> blends;
  // Vertices from before the frame that moved onto a cut (CutOptions::snap),
  // their new place over the vertices before the frame.
  std::vector<std::pair<int, VertexBlend>> relocated;
  // Advances that tore (E_r >= E_f) but could not be cut, and why.
  std::vector<std::string> skipped;
  bool changed() const { return !events.empty(); }
};

class Tearing {
 public:
  // `mesh`: the sheet at the start (its pattern's bounding box sizes the
  // fiber texture, its mean edge length the advances). Throws
  // std::invalid_argument for bad parameters.
  Tearing(const mesh::SheetMesh& mesh, const TearingParams& params, std::uint64_t seed);

  // Tests the frame's candidates (tips, `junctions`, borders of held areas
  // with held[v] != 0, inward corners; of a tear's lips only its tip and the
  // former tips where it turned by more than branchAngle) with the elastic step's `forces` and
  // cuts `mesh` where E_r >= E_f. A cut that cannot be made (the direction
  // leaves the sheet at once) is skipped and the mesh left as it was.
  TearFrameResult step(mesh::SheetMesh& mesh, const std::vector<int>& junctions,
                       const std::vector<char>& held, const VertexForces& forces);

  // Makes the given advances (another Tearing's, on another mesh of the
  // same pattern) again on `mesh`: a started tear from the boundary vertex
  // nearest its start, each advance to its s_{t+1}. What a sheet handed
  // over to a finer mesh keeps of its tears. Only on a Tearing without
  // tears (std::logic_error otherwise).
  TearFrameResult replay(mesh::SheetMesh& mesh, const std::vector<TearEvent>& events,
                         const std::vector<char>& held);

  // The crumpling model's sheet (docs/TEARING.md "The crumpling
  // model torn"): its cuts are made in S_G (paper::cutGeometricMesh) and S_P
  // is rebuilt from S_G every animation step, with new vertex numbers. This
  // finds each tear's tip again on `mesh` (the boundary vertex at the last
  // point of its cut) and its lips (boundary vertices within `lipTolerance`
  // of a cut, but for the former tips where it turned by more than
  // branchAngle). Throws std::runtime_error when a tip is not a vertex of
  // the mesh.
  void rebind(const mesh::SheetMesh& mesh, double lipTolerance);
  // Replaces the cuts of the last cuts.size() advances by the given
  // polylines (how S_G took them); the detail path is walked again between
  // the new ends where they moved. Throws std::invalid_argument for more
  // cuts than advances or a cut of fewer than two points.
  void recut(const std::vector<std::vector<Vec2>>& cuts);

  // Every advance so far, in order.
  const std::vector<TearSegment>& segments() const { return segments_; }
  // The tip vertex of each tear, -1 once it has torn through to the boundary.
  const std::vector<int>& tips() const { return tips_; }
  // Where each tear started (kind of its first candidate).
  const std::vector<CandidateKind>& startKinds() const { return startKinds_; }
  const FiberTexture& fibers() const { return fibers_; }
  double edgeLength() const { return edgeLength_; }

  // Checkpoint and resume (docs/CHECKPOINT.md): the tears (tips, lips, start kinds,
  // every advance) and the edge length the advances are measured in, for a
  // Tearing made again with the same parameters and seed on a mesh of the
  // same pattern (its fiber texture depends on those only). restoreState
  // throws CorruptDataError for a malformed state.
  void saveState(StateWriter& out) const;
  void restoreState(StateReader& in);

 private:
  // Cuts `mesh` from `vertex` to `to` as event `e` (e.tear < 0: a new
  // tear) and records it in `result`; false when the cut cannot be made.
  bool cutTo(mesh::SheetMesh& mesh, int vertex, const Vec2& to, TearEvent e,
             const std::vector<char>& held, TearFrameResult& result);

  TearingParams params_;
  FiberTexture fibers_;
  double edgeLength_ = 0.0;
  std::vector<int> tips_;
  std::vector<char> lip_;  // per vertex: on a tear's lip (not a new candidate)
  std::vector<CandidateKind> startKinds_;
  std::vector<TearSegment> segments_;
};

// Per-vertex values carried over a frame's cuts: values[v] for the old
// vertices (their blend for the moved ones), the blends for the appended.
std::vector<Vec3> blendValues(const std::vector<Vec3>& values,
                              const std::vector<VertexBlend>& blends,
                              const std::vector<std::pair<int, VertexBlend>>& relocated);

}  // namespace crumple::tear
