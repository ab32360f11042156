#pragma once
// Handles: each binds an animated node to a vertex of the sheet, optionally
// with tangent-plane control where the node's rotation drives 2-4 neighbour
// vertices (paper Sec. 4, thesis 2.3.1).
#include <functional>
#include <string>
#include <vector>

#include "crumple/core/state_io.hpp"
#include "crumple/core/types.hpp"
#include "crumple/io/animation.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/sim/elastic_sheet.hpp"

namespace crumple::model {

struct BoundHandle {
  std::string name;
  std::string node;
  int vertex = -1;
  // Tangent-plane control: neighbour vertices and their offsets from the
  // handle vertex in the node's frame at bind time.
  std::vector<int> tangentVertices;
  std::vector<Vec3> tangentOffsets;
  // A finger's contact patch ([[handles]] patch_radius): points of the
  // sheet at patchRadius (m) around the handle, each inside a triangle, and
  // their offsets from the handle in the node's frame. 0: tangent vertices.
  double patchRadius = 0.0;
  struct PatchPoint {
    int triangle = -1;
    Vec3 weights = Vec3::Zero();
    Vec3 offset = Vec3::Zero();
  };
  std::vector<PatchPoint> patch;
  Quat bindRotation = Quat::Identity();
  double releaseTime = 0.0;
  bool releases = false;
  int tangentCount =
      -1;  // requested tangent-plane vertex count (0 = automatic), -1 = no tangent control
};

class HandleRig {
 public:
  // Binds every handle of the scene to the sheet at time t0 (the first frame).
  // Throws InputError (naming the scene file and handle) for a node the
  // animation does not have, or two handles on one vertex.
  HandleRig(const io::SceneSpec& scene, const io::AnimationScene* animation,
            const mesh::SheetMesh& sheet, double t0);

  const std::vector<BoundHandle>& handles() const { return handles_; }
  // Handles bind to mesh vertices: where the vertex is more than 1e-6 m from
  // the requested pattern point, or from the node at the first frame (the
  // vertex then jumps onto the track before the first step), one line says
  // by how much.
  const std::vector<std::string>& bindWarnings() const { return warnings_; }
  // Position of the handle's node at time t (world, metres).
  Vec3 target(std::size_t handle, double t) const;
  // Every pinned vertex and where it must be at time t: on its node, unless
  // the nodes pull the sheet beyond its reach (reachExcess). Each handle's
  // pin comes first, its tangent-plane pins right after it (the crumpling
  // model moves them with a handle that lags, paper::HybridSheet).
  void pins(double t, std::vector<sim::Pin>& out) const;
  // The sheet's reach (stability): a rectangular sheet that cannot
  // tear cannot hold two handles farther apart than their pattern points
  // (times 1 + kReachSlack). Where the nodes ask for more, the handle whose
  // node has moved farther from its first-frame position stops on that
  // reach and lags behind its node; this is how far (m), 0 within reach.
  // Off (always 0) for outlines, pattern meshes and sheets that tear.
  double reachExcess(std::size_t handle, double t) const;
  static constexpr double kReachSlack = 1e-3;
  // The hybrid model rebuilds its simulation mesh S_P as the sheet crumples:
  // handle vertices keep their indices, tangent-plane vertices are chosen
  // again on the new mesh at time t, their offsets measured from where they
  // are now in the node's frame at t, so the pins move on continuously.
  void rebindTangents(const mesh::SheetMesh& sheet, double t);
  // The sheet was replaced by another mesh of the same pattern (a torn
  // crumpling-model sheet handed over to the elastic model): handle h holds
  // vertex handleVertices[h] of `sheet` from now on, and the tangent-plane
  // vertices are chosen again as by rebindTangents.
  void rebind(const mesh::SheetMesh& sheet, const std::vector<int>& handleVertices, double t);
  // Fingers as contact patches: a handle with a patch radius pins only its
  // vertex, and holds the points of the sheet at that radius around its
  // pattern point (six directions, those inside the pattern) as grips
  // (sim::Grip) that turn with its node. Their grips at time t, each drawn
  // with `stiffness` (N/m) to where the handle's target and node rotation
  // put it, anchored on the handle's vertex.
  void grips(double t, double stiffness, std::vector<sim::Grip>& out) const;
  // The patches bound again on a mesh whose triangles changed (a cut) at
  // time t; the tangent-plane vertices stay.
  void rebindPatches(const mesh::SheetMesh& sheet, double t);
  // Moves pinned vertices onto their targets (called once before simulation).
  void snap(double t, std::vector<Vec3>& positions) const;
  // Checkpoint and resume: each handle's vertex, tangent-plane
  // vertices and offsets and bind rotation, for a rig bound again from the
  // same scene. restoreState throws CorruptDataError for another rig's.
  void saveState(StateWriter& out) const;
  void restoreState(StateReader& in);

 private:
  // The held handles' positions at time t, limited to the sheet's reach;
  // `held` says which handles hold at t.
  std::vector<Vec3> heldTargets(double t, std::vector<char>& held) const;
  // Binds h's patch on `sheet` at time t ([[handles]] patch_radius).
  void bindPatch(BoundHandle& h, const mesh::SheetMesh& sheet, double t) const;

  const io::AnimationScene* animation_;
  std::vector<BoundHandle> handles_;
  bool reachLimit_ = false;
  std::vector<Vec3> bindTargets_;  // each node's position at the first frame
  std::vector<Vec2> bindPattern_;  // each handle's pattern point (else its vertex's)
  std::vector<std::string> warnings_;
};

// Neighbour vertices that define the tangent plane at `vertex` (thesis 2.3.1):
// 2 at a corner of the pattern, 3 on its border, 4 inside; `count` > 0 forces
// the number. Chosen among the one-ring by pattern direction, deterministic.
std::vector<int> tangentNeighbours(const mesh::SheetMesh& sheet, int vertex, int count);

}  // namespace crumple::model
