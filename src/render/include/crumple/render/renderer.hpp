#pragma once
// The interface both renderers implement (docs/RENDERING.md): one render()
// from a frame's scene and sheet to one rendered image, for the OSMesa
// preview rasteriser and the Embree path tracer alike. The caller picks the
// backend once, at construction (makeRenderer), and never branches on it
// afterwards.
//
// Per frame, each backend validates its input, builds the shared render
// geometry (the sheet re-centred on its bounding box, its shading normals,
// the tear patches drawn instead of their triangles, the ground square and
// the props; render_geometry.hpp) and draws it its own way.
#include <cstdint>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "crumple/core/image.hpp"
#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/render/aov.hpp"
#include "crumple/render/view.hpp"

namespace crumple::render {

// The two renderers behind the Renderer interface.
enum class Backend { Osmesa, Embree };

// What a renderer is made with: fixed for its lifetime, one shot's worth.
struct RendererOptions {
  // The rasteriser's image size (its offscreen context); the camera's must
  // match it. The path tracer renders at the camera's resolution.
  int width = 640;
  int height = 480;
  int samplesPerPixel = 16;  // path tracer: >= 1
  int maxBounces = 4;        // path tracer: diffuse bounces after the first hit
  std::uint64_t seed = 0;    // path tracer: with the frame, keys the sample streams
};

// What changes from one frame to the next besides the scene and the sheet.
struct FrameSettings {
  int frame = 0;  // the frame number (keys the path tracer's sample streams)
  // The structure view drawn over the sheet (StructureOverlay in view.hpp):
  // the rasteriser's only; the path tracer rejects a non-empty one.
  const StructureOverlay* overlay = nullptr;
  // The AOVs to compute beside the image (aov.hpp), each once: the path
  // tracer's only; the rasteriser rejects a non-empty list.
  std::vector<Aov> aovs;
};

// One rendered frame, whatever the backend: a linear float image (EXR) and
// an 8-bit sRGB picture (PNG), each exactly what the backend made. A
// backend renders one of the two; the other is converted from it on first
// use (so a frame the rasteriser writes only as PNG is never decoded).
// Like a renderer, used by one thread at a time.
class RenderedImage {
 public:
  // A frame rendered as linear RGB premultiplied by alpha (the path tracer);
  // `background` (linear) is the colour of its uncovered pixels in srgb8().
  RenderedImage(ImageRGBAF linear, const Vec3& background);
  // A frame rendered as 8-bit sRGB with straight alpha (the rasteriser).
  explicit RenderedImage(ImageRGBA8 srgb8);

  // Linear RGB premultiplied by alpha (OpenEXR's convention), rows top to
  // bottom, alpha = coverage by paper, ground or props: the backend's own
  // image, or decodeSrgb8 (premultiplied) of its 8-bit one.
  const ImageRGBAF& linear() const;
  // 8-bit sRGB with straight alpha (PNG frames): the backend's own 8-bit
  // image byte for byte, or toSrgb8(linear(), background) of its float one.
  const ImageRGBA8& srgb8() const;

  // The frame's AOVs when FrameSettings asked for some, else nullptr.
  const AovImage* aovs() const { return aovs_ ? &*aovs_ : nullptr; }
  void setAovs(AovImage aovs) { aovs_ = std::move(aovs); }

 private:
  Vec3 background_ = Vec3::Zero();
  mutable std::optional<ImageRGBAF> linear_;
  mutable std::optional<ImageRGBA8> srgb8_;
  std::optional<AovImage> aovs_;
};

// A renderer: one frame at a time (not thread-safe; one per thread).
class Renderer {
 public:
  Renderer() = default;
  virtual ~Renderer() = default;
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Draws the sheet (positions, triangles, pattern as texture coordinates)
  // with the scene's camera, lights, ground and props. Throws
  // std::invalid_argument on inconsistent or non-finite input
  // (validateRenderInput and the backend's own checks) and
  // std::runtime_error when the backend fails.
  virtual RenderedImage render(const RenderScene& scene, const mesh::SheetMesh& sheet,
                               const FrameSettings& settings, RenderPass pass) = 0;

  // The backend this renderer is.
  virtual Backend backend() const = 0;

  // Samples the last render() dropped as non-finite (the path tracer counts
  // them; the rasteriser drops none).
  virtual std::uint64_t droppedSamples() const = 0;
};

// A renderer of the given backend (OsmesaRenderer or EmbreeRenderer).
// Throws as their constructors do.
std::unique_ptr<Renderer> makeRenderer(Backend backend, const RendererOptions& options);

// Premultiplied linear RGBA -> 8-bit sRGB with straight alpha (PNG frames):
// colour = rgb / alpha encoded with linearToSrgb8, alpha rounded to 8 bits;
// pixels with alpha 0 get `background` (linear) encoded, alpha 0.
ImageRGBA8 toSrgb8(const ImageRGBAF& image, const Vec3& background);

}  // namespace crumple::render
