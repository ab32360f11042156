#pragma once
// The final renderer: a unidirectional path tracer on Embree 3 (RenderScene in
// view.hpp has the scene, its radiometry and the paper material).
//
// - Camera: pinhole or thin lens (Camera::apertureRadius, focusDistance);
//   pixel (i, j) covers [i, i+1) x [j, j+1), rows top to bottom; each sample
//   is a point of the pixel (box filter).
// - Geometry: the sheet (two-sided paper, shading normals from
//   shadingNormals(), the texture's alpha cutting it exactly through Embree
//   filter functions, for camera, bounce and shadow rays), the ground square
//   and the props (opaque two-sided diffuse).
// - Lights: next-event estimation for every light (directional, sun disc,
//   point, area) with shadow rays, the uniform environment sampled by the
//   BSDF, multiple importance sampling between light and BSDF sampling for
//   the sun disc and area lights; area lights are not seen by camera rays.
// - Deterministic: every random number is a pure function of (seed, frame,
//   pixel, sample, dimension), tiles are independent, so the image is
//   byte-identical for any thread count (crumple::threadCount()).
//
// Output: linear RGB premultiplied by alpha (alpha = the fraction of the
// pixel's samples whose camera ray hits geometry); uncovered pixels are
// (0, 0, 0, 0). Beauty: radiance; Albedo: the first hit's albedo.
#include <cstdint>
#include <memory>
#include <vector>

#include "crumple/core/image.hpp"
#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/render/aov.hpp"
#include "crumple/render/renderer.hpp"
#include "crumple/render/view.hpp"

namespace crumple::render {

// One path-traced frame's settings (the Renderer interface takes them from
// RendererOptions and FrameSettings).
struct PathTraceSettings {
  int samplesPerPixel = 16;  // >= 1
  int maxBounces = 4;        // diffuse bounces after the first hit (0 = direct light only)
  std::uint64_t seed = 0;    // with frame: keys the per-pixel sample streams
  int frame = 0;
  RenderPass pass = RenderPass::Beauty;
  std::vector<Aov> aovs;  // computed from the same camera rays (aov.hpp); each once
};

class EmbreeRenderer final : public Renderer {
 public:
  // Creates the Embree device; its BVH builds use crumple::threadCount()
  // threads (as set when the renderer is created). Throws std::runtime_error
  // naming Embree's error when it cannot. The Renderer interface's renders
  // use the options' samples per pixel, bounces and seed (not its size).
  explicit EmbreeRenderer(const RendererOptions& options = {});
  ~EmbreeRenderer() override;

  // Renders one frame at the camera's resolution. Throws
  // std::invalid_argument on inconsistent or non-finite input (as
  // OsmesaRenderer does) and std::runtime_error on an Embree failure. No NaN
  // or Inf is ever written: a non-finite sample is dropped and counted
  // (droppedSamples()).
  // With `aovs` not null, settings.aovs' channels go there (makeAovImage's
  // order: aov.hpp).
  ImageRGBAF render(const RenderScene& scene, const mesh::SheetMesh& sheet,
                    const PathTraceSettings& settings, AovImage* aovs = nullptr);

  // The Renderer interface: the render above with the options' settings and
  // the frame's number, pass and AOVs; the rendered image's linear() is its
  // image, srgb8() toSrgb8 of it on the scene's background and aovs() the
  // AOVs. Throws std::invalid_argument on a non-empty overlay.
  RenderedImage render(const RenderScene& scene, const mesh::SheetMesh& sheet,
                       const FrameSettings& settings, RenderPass pass) override;

  // Backend::Embree.
  Backend backend() const override { return Backend::Embree; }

  // Samples dropped as non-finite by the last render().
  std::uint64_t droppedSamples() const override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  RendererOptions options_;
};

}  // namespace crumple::render
