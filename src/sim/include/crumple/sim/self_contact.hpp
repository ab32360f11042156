#pragma once
// Self-contact of the sheet (docs/CONTACTS.md): vertex-triangle proximity
// pairs between parts of the sheet that lie on top of each other. FCL's
// dynamic AABB tree over the triangles (their boxes grown by the reach) is
// the broad phase; triangle pairs that share a vertex are skipped, and the
// exact vertex-triangle distances follow. Material neighbours (pattern
// distance below kSelfContactRestExclusion thicknesses) are not contacts:
// paper folded onto itself needs at least an arc of about pi/2 thicknesses
// to come back to its other layer, so nearer points are the same layer.
#include <array>
#include <memory>
#include <vector>

#include "crumple/core/types.hpp"

namespace crumple::sim {

inline constexpr double kSelfContactRestExclusion = 2.0;  // thicknesses of pattern distance

// A vertex near a triangle of another layer of the sheet.
struct SelfContactPair {
  int vertex = -1;
  int triangle = -1;
  std::array<double, 3> weights{};  // barycentric coordinates of the closest point
  double distance = 0.0;            // from the vertex to the closest point (m)
  // Unit normal of the contact plane: the triangle's face normal, on the
  // vertex's side, when the vertex lies over the face (a face contact);
  // else from the closest point (on an edge or corner) toward the vertex.
  Vec3 normal = Vec3::UnitY();
  bool face = false;
};

// An edge of the sheet that passes through a triangle of another layer: two
// layers crossed, which self-contact exists to prevent (the vertex-triangle
// pairs above cannot see it once an edge is through).
struct SelfCrossing {
  int a = -1;  // the edge's vertices, a < b
  int b = -1;
  int triangle = -1;
  double depth = 0.0;  // how far the edge's shorter part reaches past the triangle's plane (m)
};

class SelfContactDetector {
 public:
  // The sheet's triangles and pattern (material coordinates, m), and the
  // contact distance (the paper's thickness, m, > 0).
  SelfContactDetector(std::vector<std::array<int, 3>> triangles, std::vector<Vec2> pattern,
                      double contactDistance);
  ~SelfContactDetector();
  SelfContactDetector(SelfContactDetector&&) noexcept;
  SelfContactDetector& operator=(SelfContactDetector&&) noexcept;

  // Every (vertex, triangle) nearer than `reach` (m, > 0) at positions xs,
  // the vertex in no triangle sharing a vertex with that triangle and not a
  // material neighbour of it; vertices with (*vertexMask)[v] == 0 are left
  // out as the vertex of a pair (pinned ones). A vertex that lies over some
  // face keeps only its face contacts: the edge of a neighbouring triangle
  // of the layer it slides on would otherwise stand in its way like a wall
  // (its plane through the edge is tilted); a vertex over no face (beside a
  // ridge or a layer's border) keeps its edge and corner contacts. Sorted by
  // (vertex, triangle): the same input gives the same pairs in the same order.
  std::vector<SelfContactPair> find(const std::vector<Vec3>& xs, double reach,
                                    const std::vector<char>* vertexMask = nullptr);
  // The pairs of a step that moves the sheet from `start` toward `end` (the
  // predictor): the broad phase boxes each triangle over both positions,
  // grown by margin / 2, and a pair is kept when its distance at `start` is
  // below margin plus how far the vertex and the triangle move. Same order
  // and mask as find() above.
  std::vector<SelfContactPair> find(const std::vector<Vec3>& start, const std::vector<Vec3>& end,
                                    double margin, const std::vector<char>* vertexMask = nullptr);
  // Every edge that passes through a triangle sharing no vertex with it
  // (segment against triangle: the endpoints strictly on both sides of its
  // plane, the crossing point inside it), material neighbours left out as in
  // find(); sorted by (a, b, triangle).
  std::vector<SelfCrossing> crossings(const std::vector<Vec3>& xs);
  // Triangle pairs the last broad phase returned (statistics).
  std::size_t broadPhasePairs() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The self-contact gate of `[contact] self = "auto"` (docs/CONTACTS.md): true
// when the triangles' unit normals spread more than `maxSpread` (rad) from
// their area-weighted mean, i.e. the sheet is folded enough for one part to
// reach another. A sheet that could reach itself without folding (a helical
// ramp) is not caught; such a scene switches self-contact on explicitly.
bool sheetIsFolded(const std::vector<std::array<int, 3>>& triangles, const std::vector<Vec3>& xs,
                   double maxSpread);

}  // namespace crumple::sim
