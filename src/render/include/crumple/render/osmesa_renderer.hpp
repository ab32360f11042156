#pragma once
// The OSMesa preview rasteriser: the scene camera, a key light with a shadow
// map, fill lights, the two-sided paper with its pattern texture, a ground
// plane, and optionally a structure overlay (flat/curved region colours,
// rulings, singular/junction/handle points). Deterministic: identical input
// gives identical bytes.
//
// Output (ImageRGBA8): rows top to bottom, sRGB-encoded colour, straight
// alpha. Alpha is coverage by paper or ground: 255 where covered, 0 for the
// background (whose RGB is scene.background encoded to sRGB), in between on
// antialiased silhouettes (4x MSAA) whose RGB is the covered samples' colour.
//
// Shading: two-sided Lambert with the radiometry of view.hpp: colour =
// albedo * (environment + sum of lights), where a directional (or sun) light
// contributes color * intensity * max(0, n.l), a point light color *
// intensity / d^2 * max(0, n.l), an area light that of a point light at its
// centre times the cosine to its normal. Paper with transmittance T reflects
// (1 - T) of the light on the seen side and lets T of the light on the other
// side through (back-lit paper glows). Shading normals: shadingNormals()
// (split across creases and around the scene's sharp vertices). An empty
// light list means one default Light{} (directional, no shadow). At most 16
// lights. The key light (first with shadow == true) casts the paper's and the
// props' shadows on everything (shadow map, orthographic and fitted to the
// casters for a directional light, perspective for a point or area light;
// PCF; slope-scaled bias). The environment is added unoccluded. The
// texture's alpha cuts the paper exactly as view.hpp says (also in the
// shadow map, so light passes through the cut).
// Paper albedo = texture * frontColor on the front (3D winding counter-
// clockwise as in the pattern) and texture * backColor on the back; the
// texture's top row is at pattern y = textureSize.y, so seen from the front
// with the pattern's +y up the image is upright and not mirrored; it repeats
// beyond textureSize. Props: flat-shaded Lambert of their colour.
//
// Determinism: byte-identical across runs, processes, renderer instances and
// LP_NUM_THREADS. The first renderer of a process sets
// GALLIUM_OVERRIDE_CPU_CAPS=sse4.1 (unless already set) so that llvmpipe
// does not use AVX/FMA and images also match across x86-64 machines with the
// same Mesa/LLVM; set it to another value (e.g. "native") beforehand to opt out.
//
// Threads: one render() at a time per renderer; render() binds the context to
// the calling thread and releases it, so renderers may live in several threads.
#include <memory>

#include "crumple/core/image.hpp"
#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/render/renderer.hpp"
#include "crumple/render/view.hpp"

namespace crumple::render {

class OsmesaRenderer final : public Renderer {
 public:
  // Creates an offscreen context of the given size. Throws std::runtime_error
  // if OSMesa cannot create a context.
  OsmesaRenderer(int width, int height);
  // The same, of the options' width and height.
  explicit OsmesaRenderer(const RendererOptions& options);
  ~OsmesaRenderer() override;

  // Draws the sheet (positions, triangles, pattern as texture coordinates)
  // and, when `overlay` is given, the structure view over it (see
  // StructureOverlay in view.hpp); a null or empty overlay gives the same
  // bytes as none. The camera's width/height must match the renderer's.
  // Throws std::invalid_argument on inconsistent or non-finite input
  // (including an overlay whose triangleColors is neither empty nor one per
  // triangle, or whose sizes are not positive) and std::runtime_error on a GL
  // failure.
  // pass = Albedo draws the albedo pass (unlit, no overlay lighting).
  ImageRGBA8 render(const RenderScene& scene, const mesh::SheetMesh& sheet,
                    const StructureOverlay* overlay = nullptr,
                    RenderPass pass = RenderPass::Beauty);

  // The Renderer interface: the render above with the frame's overlay; the
  // rendered image's srgb8() is its 8-bit image and linear() that image
  // decoded (decodeSrgb8, premultiplied).
  RenderedImage render(const RenderScene& scene, const mesh::SheetMesh& sheet,
                       const FrameSettings& settings, RenderPass pass) override;

  // Backend::Osmesa.
  Backend backend() const override { return Backend::Osmesa; }

  // 0: the rasteriser drops no samples.
  std::uint64_t droppedSamples() const override { return 0; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace crumple::render
