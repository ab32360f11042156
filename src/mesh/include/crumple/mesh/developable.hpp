#pragma once
// Render-time refinement of the crumpling model's curved regions
// (docs/RENDERING.md "Refinement"). The model simulates S_P, a coarse
// triangle mesh in which each curved region of S_G is a strip of rulings
// (paper Sec. 3.2): quads between two boundary vertices, split at their
// barycentre, or triangles fanning from a singular apex. Drawn as they are,
// those strips are polygonal at high resolution. The refinement replaces the
// strips by finer ones whose sub-rulings come from the same pencil of lines
// in the pattern, shaped by the paper's cubic boundary curve (Sec. 6.2) and
// kept exactly isometric to the pattern: every sub-cell is a rigid copy of
// its pattern polygon, folded about its sub-rulings (a developable surface is
// ruled with a tangent plane constant along each ruling; thesis 2.2.1). Flat
// regions, creases, singular vertices and handles stay as they are, bit for
// bit.
#include <array>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "crumple/core/types.hpp"
#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/mesh/tear_patches.hpp"

namespace crumple::mesh {

// A curved region of S_G as its ordered rulings (paper Sec. 3.2, R_C), in
// the vertex indices of the mesh it is refined on: face k lies between
// rulings k and k + 1, the `a` ends on one side and the `b` ends on the
// other (a triangle where the two rulings share an end).
struct CurvedRegion {
  int region = -1;  // the mesh's region id of the region's triangles
  int apex = -1;    // the singular vertex all rulings pass through, else -1
  std::vector<std::array<int, 2>> rulings;
};

// The developable structure of a frame: its curved regions.
struct DevelopableStructure {
  std::vector<CurvedRegion> regions;
};

// Checks a structure against its mesh: region ids, vertex indices in range,
// rulings of two distinct vertices, a region's rulings at least two. Returns
// "" when valid, else the first problem found.
std::string validate(const DevelopableStructure& structure, const SheetMesh& mesh);

// A pinhole view for the screen-space density: the size of a pixel at a
// point x is pixelAngle * max(znear, (x - eye) . forward).
struct ScreenMetric {
  Vec3 eye = Vec3::Zero();
  Vec3 forward{0.0, 0.0, -1.0};  // unit view axis
  double pixelAngle = 1e-3;      // 2 tan(yfov / 2) / height in pixels
  double znear = 1e-3;           // m
};

enum class RefineMode {
  Off,    // the mesh as it is
  Auto,   // sub-cells from the fold angle (and the screen, when given)
  Fixed,  // `cells` sub-cells per face
};

struct RefineOptions {
  RefineMode mode = RefineMode::Auto;
  int cells = 8;  // Fixed: sub-cells per S_G face
  // Auto: the largest fold angle between neighbouring sub-cells (rad). A
  // silhouette along the sheet's border turns by about as much from one
  // segment to the next; 1.8 degrees keeps it within 2 with a margin.
  double maxAngle = 0.031415926535897934;  // 1.8 degrees
  // Auto with a screen: the largest gap between a sub-cell's chord and the
  // curve it stands for, in pixels.
  double pixelTolerance = 0.25;
  int maxCells = 64;  // per S_G face
  // The isometry guard: the refined mesh's mean length error (c_mean, paper
  // Table IV) stays within the source's + this (fraction); runs are left
  // unrefined, the worst closure first, until it does.
  double lengthBudget = 1e-4;
  std::optional<ScreenMetric> screen;
};

struct RefineStats {
  int regions = 0;       // curved regions in the structure
  int runs = 0;          // runs of refinable faces (between fixed rulings)
  int refinedRuns = 0;   // runs refined
  int guardedRuns = 0;   // runs the isometry guard left unrefined
  int roughRuns = 0;     // runs left unrefined: their folds came out no smoother than S_P's
  int skippedFaces = 0;  // S_G faces that cannot be refined (a side inside the sheet, a tear, ...)
  int largestCells = 0;  // the most sub-cells of a face
  double largestFold = 0.0;         // rad, the largest fold angle between sub-cells
  double largestClosure = 0.0;      // m, the largest closure error blended out
  double lengthErrorSource = 0.0;   // c_mean of the source mesh
  double lengthErrorRefined = 0.0;  // c_mean of the refined mesh
};

struct RefinedSheet {
  // The source's vertices keep their indices (a refined quad's barycentre
  // stays, unused; a refined run's inner ruling ends move onto the folded
  // surface); the sub-ruling ends follow. The source's triangles that stay
  // come first, in their order; the sub-cells' follow.
  SheetMesh mesh;
  std::vector<int> triangleOfSource;  // per source triangle: its index in `mesh`, -1 if replaced
  std::vector<int>
      sourceOfTriangle;  // per triangle of `mesh`: the source triangle, -1 for a sub-cell
  RefineStats stats;
};

// Refines the curved regions of `structure` on `sheet` (S_P). `pinned`
// vertices (handles, singular vertices) and the triangles in `locked`
// (those with a tear patch) stay as they are, and so do the faces around
// them. Deterministic. Throws std::invalid_argument for a structure
// `validate` rejects. Off, or no structure: the sheet as it is.
RefinedSheet refineDevelopable(const SheetMesh& sheet, const DevelopableStructure& structure,
                               const RefineOptions& options, std::span<const int> pinned = {},
                               std::span<const int> locked = {});

// c_mean (paper Table IV): the mean over the edges of the triangles of
// |l - L| / L, l the 3D length and L the pattern length; 0 without edges.
double meanLengthError(const SheetMesh& mesh);

// The atlas of the refined sheet: each patch moved to its triangle's new
// index (tears lock their triangles, so none was replaced). Throws
// std::invalid_argument when a patch's triangle was replaced.
TearAtlas remapTearAtlas(const TearAtlas& atlas, const RefinedSheet& refined);

}  // namespace crumple::mesh
