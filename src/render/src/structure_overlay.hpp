#pragma once
// Private to the render module: turns a StructureOverlay into screen-space
// triangles (clip-space vertices with flat sRGB colours) for the rasteriser.
// Pure CPU code in double precision; no GL.
#include <array>
#include <cstdint>
#include <vector>

#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/render/view.hpp"

namespace crumple::render::detail {

struct OverlayVertex {
  std::array<float, 4> clip;          // clip-space position
  std::array<std::uint8_t, 4> color;  // sRGB-encoded, alpha 255
};

struct OverlayGeometry {
  std::vector<OverlayVertex> lines;   // triangles; drawn depth-tested
  std::vector<OverlayVertex> points;  // triangles, far to near; drawn over everything
};

// Throws std::invalid_argument unless triangleColors is empty or has one
// colour per triangle, every coordinate and colour is finite and both sizes
// are positive and finite.
void validateOverlay(const StructureOverlay& overlay, std::size_t triangleCount);

// `camera` and `viewProj` are those of the main pass, whose world is shifted
// by -origin (the renderer draws relative to the paper's centre); the overlay's
// and the sheet's coordinates are world coordinates.
OverlayGeometry buildOverlayGeometry(const StructureOverlay& overlay, const mesh::SheetMesh& sheet,
                                     const Camera& camera, const Mat4& viewProj,
                                     const Vec3& origin);

}  // namespace crumple::render::detail
