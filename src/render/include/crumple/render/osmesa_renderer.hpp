#pragma once
// The OSMesa preview rasteriser: the scene camera, a key light with a shadow
// map, fill lights, the two-sided paper with its pattern texture, a ground
// plane. Deterministic: identical input gives identical bytes.
#include <memory>

#include "crumple/core/image.hpp"
#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/render/view.hpp"

namespace crumple::render {

class OsmesaRenderer {
 public:
  // Creates an offscreen context of the given size. Throws std::runtime_error
  // if OSMesa cannot create a context.
  OsmesaRenderer(int width, int height);
  ~OsmesaRenderer();
  OsmesaRenderer(const OsmesaRenderer&) = delete;
  OsmesaRenderer& operator=(const OsmesaRenderer&) = delete;

  // Draws the sheet (positions, triangles, pattern as texture coordinates).
  // The camera's width/height must match the renderer's.
  ImageRGBA8 render(const RenderScene& scene, const mesh::SheetMesh& sheet);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace crumple::render
