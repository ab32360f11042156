#pragma once
// Tearing the geometric layer S_G (thesis 3.3.3, "Remeshing", Figs.
// 3.20-3.23): a tear's advance from s_t to s_{t+1} cuts S_G, so that the
// crumpling model goes on with the torn sheet. The pattern boundary gains
// both lips and s_{t+1} (an outline corner); S_P, rebuilt from S_G,
// resamples them as any other outline edge.
//
// The three structure cases: s_{t+1} inside a flat region (case 3,
// Fig. 3.23) updates the region's coarse triangulation. Inside a curved
// region (case 2, Fig. 3.22) or a cone whose apex was s_t (case 1, Fig.
// 3.21), the region the advance crosses is first turned into flat triangles
// (its rulings' quads split on a diagonal, every vertex kept where it is) and
// then cut as in case 3; the next geometric step re-segments them (flat
// regions are maximal coplanar sets, compression makes rulings again). See
// docs/TEARING.md "The crumpling model torn".
//
// The lips are a slit of width `kerf` in the pattern (a V at s_{t+1}) so
// that the outline stays a simple polygon: every S_G query by pattern point
// (outline segment, boundary curve, point in face) keeps one answer.
#include <functional>
#include <numbers>
#include <optional>
#include <vector>

#include "crumple/core/types.hpp"
#include "crumple/paper/geometric_mesh.hpp"

namespace crumple::paper {

struct GeometricCutOptions {
  // Width of the slit between the two lips in the pattern (m): far below
  // the tear's detail (texels of 0.25 mm) and the fibers, far above the
  // S_G tolerances (1e-9 of the sheet).
  double kerf = 1e-5;
  // cutAlong's snap over S_G's coarse edges (a fraction of an edge): S_G's
  // vertices never move (singular points are permanent), so the cut goes
  // through a vertex it passes this near, rather than leave a lip piece of a
  // fraction of a millimetre.
  double snap = 0.002;
  // Where the sheet is in 3D, and how fast it moves, at a pattern point: the
  // finer surface the cut's new vertices are placed on (the crumpling
  // model's S_P). Returns false where it does not know; nullptr, or false:
  // interpolated in the S_G triangle the vertex splits.
  std::function<bool(const Vec2& pattern, Vec3& position, Vec3& velocity)> surface;
  // The largest turn (rad) from `previousDirection` a cut may take: the
  // slit's two copies of s_t meet where the lips' kerf lines cross, which a
  // tear turning back on itself does not have.
  double maxTurn = 0.5 * std::numbers::pi;
};

struct GeometricCutResult {
  int tip = -1;  // the S_G vertex at s_{t+1}
  // The cut's centre line from s_t to s_{t+1} (pattern, m): the points where
  // it crosses S_G's edges, before the lips part by the kerf.
  std::vector<Vec2> cut;
  int regionsFlattened = 0;  // curved regions turned into flat triangles (cases 1-2)
};

// Cuts S_G from the outline point `from` (an S_G boundary vertex, or a point
// on an S_G outline edge, which becomes one) to the pattern point `to`
// inside the sheet. `previousDirection` (pattern, unit): the direction of
// the tear's last advance when `from` is its tip, so that s_t's two copies
// sit where both lips' kerf lines meet. Returns std::nullopt, leaving `g`
// as it was, when the cut reaches the outline again (the sheet would come
// apart: S_G is one piece with one outline). Throws std::invalid_argument
// when `from` is not on the outline, the cut leaves the sheet at once, or
// S_G would not be valid afterwards (validate), or the cut turns by more
// than options.maxTurn from previousDirection, leaving `g` as it was.
std::optional<GeometricCutResult> cutGeometricMesh(
    GeometricMesh& g, const Vec2& from, const Vec2& to, const GeometricCutOptions& options = {},
    const std::optional<Vec2>& previousDirection = std::nullopt);

}  // namespace crumple::paper
