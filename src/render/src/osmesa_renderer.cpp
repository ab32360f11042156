// The OSMesa preview rasteriser (llvmpipe, GL 3.3 core, GLSL 330).
//
// Passes per frame, over the shared render geometry (render_geometry.hpp):
// (1) a depth-only shadow map of the paper seen from the key light (the first
// light with shadow == true; osmesa/shadow_map.cpp); (2) ground and paper into
// a 4x multisampled framebuffer, two-sided Lambert shading with PCF shadows,
// sRGB encoded in the shader (osmesa/shaders.cpp); (2b) when a structure
// overlay is given, its lines (depth-tested) and points (on top) as flat
// screen-space triangles into the same framebuffer; (3) resolve, read back,
// flip to top-down rows and turn the coverage-weighted colours into straight
// alpha (osmesa/draw_passes.cpp). The context, programs and framebuffers are
// made once per renderer (osmesa/gl_setup.cpp).
//
// Link OSMesa only: with libGL linked too every GL call is a no-op.
#include "crumple/render/osmesa_renderer.hpp"

#include <stdexcept>
#include <string>

#include "osmesa/osmesa_impl.hpp"

namespace crumple::render {

namespace {

// The preview's own checks on top of validateRenderInput.
void validateInput(const RenderScene& scene, const mesh::SheetMesh& sheet, int width, int height) {
  const Camera& cam = scene.camera;
  if (cam.width != width || cam.height != height)
    throw std::invalid_argument("OsmesaRenderer: camera is " + std::to_string(cam.width) + "x" +
                                std::to_string(cam.height) + " but the renderer is " +
                                std::to_string(width) + "x" + std::to_string(height));
  if (static_cast<int>(scene.lights.size()) > gl::kMaxLights)
    throw std::invalid_argument("OsmesaRenderer: at most " + std::to_string(gl::kMaxLights) +
                                " lights");
  validateRenderInput(scene, sheet, "OsmesaRenderer");
}

// The first light casting shadows, or -1.
int keyLightIndex(const std::vector<Light>& lights) {
  for (std::size_t i = 0; i < lights.size(); ++i)
    if (lights[i].shadow) return static_cast<int>(i);
  return -1;
}

}  // namespace

ImageRGBA8 OsmesaRenderer::Impl::render(const RenderScene& scene, const mesh::SheetMesh& sheet,
                                        const StructureOverlay* overlay, RenderPass pass) {
  validateInput(scene, sheet, width, height);
  if (overlay != nullptr) {
    detail::validateOverlay(*overlay, sheet.triangles.size());
    if (overlay->empty()) overlay = nullptr;  // the same bytes as no overlay
  }
  const gl::CurrentContext current(context, osmesaBuffer, width, height);

  // Tear patches are drawn instead of their triangles (view.hpp), except in
  // the structure view with triangle colours, which shows the mesh.
  const bool overlayColors = overlay != nullptr && !overlay->triangleColors.empty();
  const detail::RenderGeometry g = detail::buildRenderGeometry(scene, sheet, !overlayColors);
  const bool hasPaper = !sheet.triangles.empty();
  uploadSheet(g, sheet, scene.tears, !scene.tears.empty() && !overlayColors);
  uploadProps(g);
  uploadGround(g);

  // The paper texture (unit 0), needed by the shadow pass of a cut paper.
  if (scene.paper.texture.pixels.empty())
    uploadTexture(defaultPaperTexture(), true);
  else
    uploadTexture(scene.paper.texture, false);

  MainPass main;
  main.alphaCut = textureHasCut;
  main.albedo = pass == RenderPass::Albedo;
  main.hasPaper = hasPaper;
  const int key = keyLightIndex(g.lights);
  if (key >= 0 && hasPaper) {
    const Light& keyLight = g.lights[static_cast<std::size_t>(key)];
    main.shadow = drawShadowMap(g, sheet, keyLight, main.alphaCut);
    main.keyLight = key;
    main.keyIsPoint = keyLight.kind != Light::Kind::Directional;
  }

  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_2D, shadowTex);
  glActiveTexture(GL_TEXTURE0);
  main.triColors = overlayColors && hasPaper;
  if (main.triColors) uploadTriangleColors(overlay->triangleColors);
  main.viewProj = projectionMatrix(g.camera) * viewMatrix(g.camera);
  drawMainPass(scene, g, main);
  if (overlay != nullptr)
    drawOverlay(detail::buildOverlayGeometry(*overlay, sheet, g.camera, main.viewProj, g.origin));
  return readBack(scene.background);
}

OsmesaRenderer::OsmesaRenderer(int width, int height) {
  if (width <= 0 || height <= 0)
    throw std::invalid_argument("OsmesaRenderer: width and height must be positive");
  gl::pinLlvmpipeCpuFeatures();
  impl_ = std::make_unique<Impl>(width, height);
}

OsmesaRenderer::OsmesaRenderer(const RendererOptions& options)
    : OsmesaRenderer(options.width, options.height) {}

OsmesaRenderer::~OsmesaRenderer() = default;

ImageRGBA8 OsmesaRenderer::render(const RenderScene& scene, const mesh::SheetMesh& sheet,
                                  const StructureOverlay* overlay, RenderPass pass) {
  return impl_->render(scene, sheet, overlay, pass);
}

RenderedImage OsmesaRenderer::render(const RenderScene& scene, const mesh::SheetMesh& sheet,
                                     const FrameSettings& settings, RenderPass pass) {
  if (!settings.aovs.empty())
    throw std::invalid_argument("OsmesaRenderer: AOVs are computed by the path tracer only");
  return RenderedImage(impl_->render(scene, sheet, settings.overlay, pass));
}

}  // namespace crumple::render
