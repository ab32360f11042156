#pragma once
// Private to the render module: the geometry both renderers draw, built once
// per frame from the scene and the sheet (buildRenderGeometry). Everything is
// relative to the sheet's bounding-box centre so that float vertex positions
// keep their precision wherever the sheet is; positions, normals and texture
// coordinates are rounded to float exactly once, here, as both backends did
// on their own before.
#include <array>
#include <cstddef>
#include <optional>
#include <vector>

#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/render/view.hpp"

namespace crumple::render::detail {

// Three floats: a position or a normal as the backends store it.
using Float3 = std::array<float, 3>;
// Two floats: a texture coordinate.
using Float2 = std::array<float, 2>;

// A vector rounded to float component by component.
inline Float3 toFloat3(const Vec3& v) {
  return {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z())};
}

// A vector made of floats, widened back to double.
inline Vec3 toVec3(const Float3& v) { return {v[0], v[1], v[2]}; }

// A corner of a piece of a tear patch.
struct PatchCorner {
  Float3 position;  // relative to the origin
  Float3 normal;    // the shading normal of the patch triangle's corner it takes
  Float2 uv;        // patternToUv of its pattern point
  Vec2 atlas;       // its position in the tear atlas, texels (mesh::atlasPosition)
};

// A triangle of a tear patch (the triangle itself or a piece of a support
// quad), drawn instead of the sheet triangle and cut by the patch's mask.
struct PatchPiece {
  std::array<PatchCorner, 3> corners;
  std::size_t triangle = 0;  // the sheet triangle its patch is drawn instead of
  Vec3 faceNormal;           // unit, of its world positions (zero when degenerate)
};

// A prop placed for this frame, relative to the origin.
struct PropGeometry {
  const PropMesh* mesh = nullptr;   // the scene's prop: triangles and colour
  std::vector<Float3> vertices;     // one per prop vertex
  std::vector<Float3> faceNormals;  // one per prop triangle, unit (zero when degenerate)
};

// One frame's render geometry (buildRenderGeometry).
struct RenderGeometry {
  Vec3 origin = Vec3::Zero();  // the sheet's bounding-box centre (zero without vertices)
  double sheetSize = 0.0;      // the bounding box's diagonal (0 without vertices)
  Camera camera;               // the scene's camera, its position relative to the origin
  // The scene's lights, or one default Light{} when it has none; positions
  // relative to the origin.
  std::vector<Light> lights;

  // The sheet: one position and texture coordinate per vertex, the shading
  // normals per triangle corner (shadingNormals) and the unit face normals
  // per triangle (zero when degenerate), all of the whole mesh.
  std::vector<Float3> positions;
  std::vector<Float2> uvs;
  std::vector<std::array<Vec3, 3>> cornerNormals;
  std::vector<Vec3> faceNormals;
  // The sheet triangles drawn as they are, in mesh order: all of them, less
  // those a tear patch is drawn instead of.
  std::vector<std::size_t> drawnTriangles;
  // The tear patches' triangles, patch by patch (empty without tears).
  std::vector<PatchPiece> patchPieces;

  std::vector<PropGeometry> props;  // every prop of the scene, in order
  // The ground square's corners (counter-clockwise seen from above) when
  // the ground is enabled: at Y = height, centred under the sheet.
  std::optional<std::array<Vec3, 4>> ground;
};

// Builds the render geometry of a validated scene and sheet
// (validateRenderInput). withTearPatches = false draws every sheet triangle
// and no patch (the rasteriser's structure view with triangle colours).
RenderGeometry buildRenderGeometry(const RenderScene& scene, const mesh::SheetMesh& sheet,
                                   bool withTearPatches);

// No motion-blur time step: the scene's own positions.
inline constexpr std::size_t kNoStep = static_cast<std::size_t>(-1);

// The render geometry at motion-blur time step `step` (< motionSteps()):
// the sheet at scene.sheetMotion[step] (its own positions when that is
// empty), the props at their motion[step] (when they move), about base's
// origin so that every step shares one frame of reference.
RenderGeometry buildStepGeometry(const RenderScene& scene, const mesh::SheetMesh& sheet,
                                 bool withTearPatches, const RenderGeometry& base,
                                 std::size_t step);

// Unit face normals of a triangle mesh (zero for a degenerate triangle): the
// face normals shadingNormals smooths.
std::vector<Vec3> faceNormals(const std::vector<Vec3>& positions,
                              const std::vector<std::array<int, 3>>& triangles);

// shadingNormals from the face normals already computed (faceNormals).
std::vector<std::array<Vec3, 3>> shadingNormals(const std::vector<Vec3>& positions,
                                                const std::vector<std::array<int, 3>>& triangles,
                                                const std::vector<Vec3>& faceNormals,
                                                double creaseAngle,
                                                const std::vector<int>& sharpVertices);

// True when some texel's alpha is below 0.5 (under 128), i.e. the bilinear
// alpha can be: the paper has cut-outs.
bool hasCutOuts(const ImageRGBA8& texture);

}  // namespace crumple::render::detail
