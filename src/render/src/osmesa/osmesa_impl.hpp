#pragma once
// Private to the rasteriser: OsmesaRenderer's state (the context, its GL
// objects and per-frame buffers) and its steps: set-up (gl_setup.cpp), the
// per-frame uploads and draw passes (draw_passes.cpp), orchestrated by
// OsmesaRenderer::Impl::render (osmesa_renderer.cpp).
#include <array>
#include <cstdint>
#include <map>
#include <vector>

#include "../render_geometry.hpp"
#include "../structure_overlay.hpp"
#include "context.hpp"
#include "crumple/render/osmesa_renderer.hpp"
#include "gl.hpp"
#include "shadow_map.hpp"

namespace crumple::render {

// The rasteriser's context, GL objects and reused per-frame buffers.
struct OsmesaRenderer::Impl {
  int width = 0;
  int height = 0;
  // Declared before the context so that it outlives it.
  std::vector<std::uint8_t> osmesaBuffer;
  gl::OsmesaContext context;

  GLuint shadowProgram = 0;
  GLuint shadowCutProgram = 0;      // the shadow pass of a paper with cut-outs
  GLuint shadowMaskProgram = 0;     // ... of tear patches
  GLuint shadowMaskCutProgram = 0;  // ... of tear patches of a paper with cut-outs
  GLuint overlayProgram = 0;
  // Main-pass programs by variant (lights, key light, key is point, ground,
  // triangle colours, alpha cut, transmission, albedo pass, tear mask).
  std::map<std::array<int, 9>, GLuint> mainPrograms;
  int shadowSize = gl::kShadowMapSmall;
  GLuint paperVao = 0, paperVbo = 0;
  GLuint groundVao = 0, groundVbo = 0;
  GLuint propVao = 0, propVbo = 0;
  GLuint patchVao = 0, patchVbo = 0;
  GLuint maskTex = 0;
  GLuint msFbo = 0, msColor = 0, msDepth = 0;
  GLuint resolveFbo = 0, resolveColor = 0;
  GLuint shadowFbo = 0, shadowTex = 0;
  GLuint paperTex = 0;
  GLuint overlayVao = 0, overlayVbo = 0;
  GLuint triColorBuffer = 0, triColorTex = 0;
  int samples = 0;

  // The texture currently uploaded (to skip re-uploading an unchanged one).
  bool textureIsRuled = false;
  bool textureHasCut = false;  // some texel's alpha < 0.5: the paper has cut-outs
  ImageRGBA8 uploadedTexture;

  std::vector<gl::Vertex> vertices;            // three per drawn sheet triangle
  std::vector<gl::PatchVertex> patchVertices;  // three per triangle of the tear patches
  std::vector<gl::Vertex> propVertices;        // three per prop triangle, all props
  std::vector<GLint> propFirst;                // first vertex of each prop
  std::vector<std::uint8_t> readback;
  std::vector<GLfloat> triColors;

  // What the main pass draws with, besides the geometry.
  struct MainPass {
    int keyLight = -1;        // the shadow-casting light's index, or -1 without shadows
    bool keyIsPoint = false;  // ... and it is a point or area light
    bool triColors = false;   // the overlay's triangle colours replace the paper's albedo
    bool alphaCut = false;    // the texture's alpha cuts the paper
    bool albedo = false;      // the albedo pass (unlit)
    bool hasPaper = false;    // the sheet has triangles
    gl::ShadowProjection shadow;
    Mat4 viewProj = Mat4::Identity();
  };

  // Creates the context, programs, buffers and framebuffers (gl_setup.cpp).
  Impl(int w, int h);

  // --- set-up (gl_setup.cpp) ---
  // The shadow and overlay programs.
  void createPrograms();
  // The main-pass program of a variant, compiled on first use.
  GLuint mainProgram(int numLights, int keyLight, bool keyIsPoint, bool ground, bool triColors,
                     bool alphaCut, bool transmit, bool albedo, bool tearMask = false);
  // The vertex arrays and buffers of the paper, ground, props, patches and overlay.
  void createGeometry();
  // The multisampled, resolve and shadow-map framebuffers.
  void createTargets();
  // The paper texture on unit 0 (skipped when unchanged); sets textureHasCut.
  void uploadTexture(const ImageRGBA8& tex, bool ruled);
  // The tear atlas's mask as a single-channel texture on kMaskUnit (GL_LINEAR,
  // clamped, level 0 only: mesh::sampleTearMask's lookup).
  void uploadMask(const mesh::TearAtlas& atlas);
  // Per-triangle albedo (linear RGB) as an RGBA32F buffer texture on unit 2.
  void uploadTriangleColors(const std::vector<Vec3>& colors);

  // --- per frame (draw_passes.cpp) ---
  // The drawn sheet triangles and, when `torn`, the tear patches and mask.
  void uploadSheet(const detail::RenderGeometry& g, const mesh::SheetMesh& sheet,
                   const mesh::TearAtlas& tears, bool torn);
  // The props, flat-shaded, three vertices per triangle.
  void uploadProps(const detail::RenderGeometry& g);
  // The ground square (two triangles), when there is one.
  void uploadGround(const detail::RenderGeometry& g);
  // The depth-only shadow map of the paper, patches and props seen from the
  // key light; returns its projection.
  gl::ShadowProjection drawShadowMap(const detail::RenderGeometry& g, const mesh::SheetMesh& sheet,
                                     const Light& key, bool alphaCut);
  // Ground, props, paper and patches into the multisampled framebuffer.
  void drawMainPass(const RenderScene& scene, const detail::RenderGeometry& g,
                    const MainPass& pass);
  // Lines depth-tested against the paper, the ground and each other, then
  // points over everything (already sorted far to near).
  void drawOverlay(const detail::OverlayGeometry& overlay);
  // Resolves, reads back and turns the coverage-weighted colours into
  // straight alpha (rows top to bottom; the background where uncovered).
  ImageRGBA8 readBack(const Vec3& background);

  // OsmesaRenderer::render.
  ImageRGBA8 render(const RenderScene& scene, const mesh::SheetMesh& sheet,
                    const StructureOverlay* overlay, RenderPass pass);
};

}  // namespace crumple::render
