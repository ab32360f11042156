#pragma once
// A frame's baked tear textures as plain data (thesis 3.3.4, Figs. 3.24-3.25):
// every triangle bordering a tear is drawn as a patch, the triangle plus a
// support rectangle beyond each of its lip edges (Fig. 3.25), cut by an alpha
// mask of the paper along the tear's detail path (T_left / T_right, Fig.
// 3.24); the masks of all patches are packed into one atlas. tear::
// bakeTearAtlas makes it, the cache carries it (cache::encodeTearAtlas,
// docs/PCACHE.md "TEAR"), both renderers draw it (docs/RENDERING.md
// "Tears"). It lives here, in mesh, because all of those modules see mesh
// and none of them sees another.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "crumple/core/types.hpp"
#include "crumple/mesh/sheet_mesh.hpp"

namespace crumple::mesh {

// A tear's lip: left or right of its cut, walking from the tear's start
// towards its tip.
enum class LipSide : std::uint8_t { Left = 0, Right = 1 };

// Where a patch's mask lies in the atlas: texels [x, x + width) x [y, y +
// height); texel (x + i, y + j) covers the pattern square origin + texelSize
// * ([i, i + 1] x [j, j + 1]).
struct AtlasRect {
  int x = 0;
  int y = 0;
  int width = 0;
  int height = 0;
  Vec2 origin = Vec2::Zero();  // m
  bool operator==(const AtlasRect& o) const {
    return x == o.x && y == o.y && width == o.width && height == o.height && origin == o.origin;
  }
};

struct TearPatch {
  int triangle = -1;             // the frame's triangle it is drawn instead of
  int tear = 0;                  // the tear it borders (the first, when several)
  LipSide side = LipSide::Left;  // its lip of that tear
  // Bit k: the edge from corner k to corner k + 1 (mod 3) is a lip edge,
  // extended by a support quad (Fig. 3.25). 0: a triangle near the tear with
  // no edge on its cut, masked only.
  std::uint8_t lipEdges = 0;
  // The outline in the pattern (m), counter-clockwise: corner 0, the two
  // outer corners of edge 0's support quad when edge 0 is a lip edge, corner
  // 1, likewise, corner 2, likewise (3 + 2 x lip edges points).
  std::vector<Vec2> polygon;
  AtlasRect rect;
  bool operator==(const TearPatch& o) const {
    return triangle == o.triangle && tear == o.tear && side == o.side && lipEdges == o.lipEdges &&
           polygon == o.polygon && rect == o.rect;
  }
};

struct TearAtlas {
  double texelSize = 2.5e-4;  // m per texel
  int width = 0;
  int height = 0;
  // width x height texels, row-major from row 0: 255 where the patch whose
  // rect holds the texel shows paper, 0 where it does not.
  std::vector<std::uint8_t> mask;
  std::vector<TearPatch> patches;  // sorted by triangle, at most one per triangle
  bool empty() const { return patches.empty(); }
  bool operator==(const TearAtlas& o) const {
    return texelSize == o.texelSize && width == o.width && height == o.height && mask == o.mask &&
           patches == o.patches;
  }
};

// The atlas position of pattern point p in `patch`'s mask, in texels: atlas
// texel (x, y) covers [x, x + 1) x [y, y + 1).
Vec2 atlasPosition(const TearAtlas& atlas, const TearPatch& patch, const Vec2& p);

// Bilinear lookup of a tear atlas's mask as OpenGL does it with GL_LINEAR
// and GL_CLAMP_TO_EDGE at level 0, at an atlas position in texels
// (atlasPosition; texel centres at x + 0.5): in [0, 1]; 1 for an empty
// atlas. What the renderers and the exports cut the paper with.
double sampleTearMask(const TearAtlas& atlas, const Vec2& position);

// A corner of one of a patch's triangles.
struct TearPatchVertex {
  Vec3 position = Vec3::Zero();  // m, this frame
  Vec2 pattern = Vec2::Zero();   // m
  int corner = 0;                // the triangle's corner whose shading normal it takes
};
using TearPatchTriangle = std::array<TearPatchVertex, 3>;

// The patch in 3D for the mesh's current positions (what both renderers
// draw): the triangle itself (its corners exactly), then two triangles per
// support quad, corner k, outer corner, outer corner and corner k, outer
// corner, corner k + 1. The quads lie in the triangle's plane: the
// triangle's affine map from the pattern to 3D, extrapolated. Winding
// counter-clockwise in the pattern, like the mesh's triangles. The patch must
// be valid for the mesh (validate below).
std::vector<TearPatchTriangle> tearPatchTriangles(const TearPatch& patch, const SheetMesh& mesh);

// The atlas's structure: a finite texel size > 0, a mask of width x height
// bytes each 0 or 255, patches sorted by triangle (each >= 0, once), tears >= 0, sides
// 0 or 1, lip edges < 8, 3 + 2 x lip edges finite polygon points, rects of
// at least one texel inside the atlas with a finite origin. Empty when
// valid, else the first problem ("patch 3: ...").
std::string validate(const TearAtlas& atlas);
// The same, and every patch's triangle in the mesh with the polygon's
// corners at the triangle's pattern corners.
std::string validate(const TearAtlas& atlas, const SheetMesh& mesh);

}  // namespace crumple::mesh
