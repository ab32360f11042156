// The Embree 3 path tracer (embree_renderer.hpp; radiometry and the paper
// material in view.hpp).
//
// Per render: the shared render geometry (render_geometry.hpp), turned into
// an Embree scene of the sheet (float positions relative to the sheet's
// bounding-box centre), the ground square and the props, with per-triangle
// shading data in flat arrays (embree/scene_build.cpp); the image split into
// 16x16 tiles pulled by the workers (crumple::parallelFor) from a shared
// counter and path traced (embree/integrator.cpp).
#include "crumple/render/embree_renderer.hpp"

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "crumple/core/parallel.hpp"
#include "embree/aov_pass.hpp"
#include "embree/integrator.hpp"
#include "embree/scene_build.hpp"
#include "render_geometry.hpp"

namespace crumple::render {

namespace {

// Checks everything render() relies on (std::invalid_argument otherwise).
void validateInput(const RenderScene& scene, const mesh::SheetMesh& sheet,
                   const PathTraceSettings& settings) {
  if (settings.samplesPerPixel < 1)
    throw std::invalid_argument("EmbreeRenderer: samplesPerPixel must be >= 1");
  if (settings.maxBounces < 0)
    throw std::invalid_argument("EmbreeRenderer: maxBounces must be >= 0");
  const Camera& cam = scene.camera;
  if (static_cast<long long>(cam.width) * cam.height > (1LL << 31) / 4)
    throw std::invalid_argument("EmbreeRenderer: image too large");
  validateRenderInput(scene, sheet, "EmbreeRenderer");
}

}  // namespace

// The device, and what the last render dropped.
struct EmbreeRenderer::Impl {
  pt::EmbreeDevice device;
  std::uint64_t dropped = 0;

  // EmbreeRenderer::render.
  ImageRGBAF render(const RenderScene& scene, const mesh::SheetMesh& sheet,
                    const PathTraceSettings& settings, AovImage* aovs);
};

ImageRGBAF EmbreeRenderer::Impl::render(const RenderScene& scene, const mesh::SheetMesh& sheet,
                                        const PathTraceSettings& settings, AovImage* aovs) {
  validateInput(scene, sheet, settings);
  dropped = 0;
  const detail::RenderGeometry geometry =
      detail::buildRenderGeometry(scene, sheet, /*withTearPatches=*/true);
  pt::FrameData f = pt::buildFrameData(scene, sheet, geometry, settings);
  const bool cutOuts =
      !scene.paper.texture.pixels.empty() && detail::hasCutOuts(scene.paper.texture);
  // Declared after f: it references f's buffers.
  const pt::ScenePtr rtcScene = pt::buildScene(device, f, cutOuts || !scene.tears.empty());

  const Camera& cam = scene.camera;
  ImageRGBAF out(cam.width, cam.height);
  if (aovs) *aovs = pt::makeAovImage(settings.aovs, cam.width, cam.height);
  const int tiles = ((cam.width + pt::kTileSize - 1) / pt::kTileSize) *
                    ((cam.height + pt::kTileSize - 1) / pt::kTileSize);
  const int workers = std::max(1, std::min(threadCount(), tiles));
  std::atomic<int> next{0};
  std::vector<std::uint64_t> droppedBy(static_cast<std::size_t>(workers), 0);
  parallelFor(
      static_cast<std::size_t>(workers),
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
          droppedBy[i] = pt::renderTiles(f, rtcScene.get(), settings, next, out, aovs);
      },
      1);
  for (const std::uint64_t d : droppedBy) dropped += d;
  return out;
}

EmbreeRenderer::EmbreeRenderer(const RendererOptions& options)
    : impl_(std::make_unique<Impl>()), options_(options) {}

EmbreeRenderer::~EmbreeRenderer() = default;

ImageRGBAF EmbreeRenderer::render(const RenderScene& scene, const mesh::SheetMesh& sheet,
                                  const PathTraceSettings& settings, AovImage* aovs) {
  return impl_->render(scene, sheet, settings, aovs);
}

RenderedImage EmbreeRenderer::render(const RenderScene& scene, const mesh::SheetMesh& sheet,
                                     const FrameSettings& settings, RenderPass pass) {
  if (settings.overlay != nullptr && !settings.overlay->empty())
    throw std::invalid_argument(
        "EmbreeRenderer: the structure view is drawn by the rasteriser only");
  PathTraceSettings pt;
  pt.samplesPerPixel = options_.samplesPerPixel;
  pt.maxBounces = options_.maxBounces;
  pt.seed = options_.seed;
  pt.frame = settings.frame;
  pt.pass = pass;
  pt.aovs = settings.aovs;
  if (pt.aovs.empty())
    return RenderedImage(impl_->render(scene, sheet, pt, nullptr), scene.background);
  AovImage aovs;
  RenderedImage image(impl_->render(scene, sheet, pt, &aovs), scene.background);
  image.setAovs(std::move(aovs));
  return image;
}

std::uint64_t EmbreeRenderer::droppedSamples() const { return impl_->dropped; }

}  // namespace crumple::render
