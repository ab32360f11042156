#pragma once
// Baking a frame's tear textures (thesis 3.3.4, Figs. 3.24-3.25): the mesh is
// cut along edges, the paper visibly parts along the detail path; every
// triangle bordering a tear becomes a patch whose alpha mask (T_left or
// T_right) keeps the paper on its side of the detail path, and whose support
// quads reach across the cut to hold the paper up to the path. The data
// (mesh::TearAtlas) is in crumple/mesh/tear_patches.hpp; docs/RENDERING.md
// "Tears" has the rules.
#include <vector>

#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/mesh/tear_patches.hpp"
#include "crumple/tear/tear_segment.hpp"

namespace crumple::tear {

using mesh::LipSide;
using mesh::TearAtlas;
using mesh::TearPatch;

struct TearAtlasParams {
  // m per texel: the detail path's resolution (FiberTextureParams::texelSize).
  double texelSize = 2.5e-4;
  // Texels added to the support quads' width beyond the detail path's
  // largest distance from its cut.
  double margin = 2.0;
  // How far (m) a lip's points may lie from the cut: 0 for a mesh cut along
  // the cut itself (cutAlong: within 1e-9 of the extent); the crumpling
  // model's lips are a slit (paper::GeometricCutOptions::kerf) whose points
  // are up to a few kerfs off the cut's centre line.
  double lipTolerance = 0.0;
};

// The patches of every tear in `segments` over the mesh they cut (a pure
// function of its inputs). A tear is the chain of its segments in list order
// (a segment that does not start where the tear's previous one ended starts
// a new chain); its sides are those of its whole detail path, continued
// beyond both ends along its cut's first and last edges. Patches:
// - each triangle with a boundary edge on a chain's cut (a lip edge: both
//   ends and midpoint on the cut polyline): a support quad beyond that edge,
//   as wide as the detail path's largest distance from the cut plus the
//   margin, widened along the edge by as much at an end where the cut turns
//   away from the quad's side, so that the quads of one lip leave no gap;
// - each other triangle nearer than that width to the cut (its side: that
//   of its points beside the cut): no quad, masked only.
// A patch's mask is 255 on texels whose centre is on its side of the path
// (leftOfPath) of every chain it borders, or whose nearest point on that
// chain's cut is one of the cut's ends (beyond a tear's ends the paper is
// whole), on a texel grid shared by all patches (texel (i, j) covers
// texelSize * [i, i + 1] x [j, j + 1]), so the two lips' masks are
// complementary texel for texel beside the cut. Throws
// std::invalid_argument for bad parameters, a segment with fewer than two
// cut or detail points, non-finite points, or a detail path that does not
// start and end (within half a texel) where its cut does; std::length_error
// for an atlas over 2^28 texels.
TearAtlas bakeTearAtlas(const mesh::SheetMesh& mesh, const std::vector<TearSegment>& segments,
                        const TearAtlasParams& params);

}  // namespace crumple::tear
