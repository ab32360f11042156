#pragma once
// What a renderer needs to draw one frame: camera, lights, ground, the paper's
// look. Shared by the OSMesa preview (and later the Embree path tracer).
#include <cstdint>
#include <optional>
#include <vector>

#include "crumple/core/image.hpp"
#include "crumple/core/types.hpp"

namespace crumple::render {

struct Camera {
  Vec3 position{0.0, 0.3, 0.6};
  Quat rotation = Quat::Identity();  // looks down local -Z, +Y up (glTF convention)
  double yfov = 0.6981317007977318;  // rad
  double znear = 0.01;               // m
  double zfar = 100.0;               // m
  int width = 640;
  int height = 480;

  // A camera at `position` looking at `target`, `up` projecting upwards in the
  // image. An `up` parallel to the view direction is replaced by the world axis
  // least aligned with it. Throws std::invalid_argument if target == position.
  static Camera lookAt(const Vec3& position, const Vec3& target, const Vec3& up, double yfov,
                       int width, int height);
};

struct Light {
  enum class Kind { Directional, Point };
  Kind kind = Kind::Directional;
  Vec3 direction{-0.4, -1.0, -0.3};  // Directional: direction the light travels (normalised on use)
  Vec3 position = Vec3::Zero();      // Point
  Vec3 color{1.0, 1.0, 1.0};         // linear RGB
  double intensity = 1.0;
  bool shadow = false;  // at most one shadow-casting light is honoured (the key)
};

struct Ground {
  bool enabled = false;
  double height = 0.0;  // world Y
  double size = 2.0;    // m, a square centred under the paper
  Vec3 color{0.55, 0.50, 0.45};
};

struct PaperLook {
  Vec3 frontColor{0.92, 0.92, 0.90};  // linear albedo multiplying the texture
  Vec3 backColor{0.92, 0.92, 0.90};
  // The printed pattern texture, addressed by pattern coordinates divided by
  // textureSize (u, v in [0, 1] over the sheet). Empty = a procedural ruled
  // paper texture (makeRuledPaperTexture).
  ImageRGBA8 texture;
  Vec2 textureSize{0.21, 0.297};  // m covered by the texture in u and v
};

// A diagnostic overlay drawn over the sheet: the structure view of the hybrid
// crumpling model (paper Fig. 2: flat regions green, curved regions magenta
// with their rulings, singular vertices red, junction vertices yellow, handles
// black). The renderer knows nothing of the model: the caller colours the
// triangles and lists the lines and points (StructurePalette has the figure's
// colours).
//
// - Triangles keep their lit, two-sided Lambert shading (and shadows) so the
//   3D shape stays readable; triangleColors only replaces the albedo.
// - Lines are flat (unlit) screen-space quads lineWidthPx wide with square
//   caps (half a width beyond each end), depth-tested against the paper and
//   the ground after a small shift towards the camera (1 + 1.5 * lineWidthPx
//   pixels of depth), so lines on the surface stay fully visible on faces up
//   to ~70 degrees from facing the camera while lines behind the paper stay
//   hidden. A line is straight in 3D: draw a curve as a polyline.
// - Points are flat discs pointSizePx across with a black rim (a pixel wide,
//   for points of 4 px and more) so that yellow reads on white paper. A point
//   is drawn whole, over everything, when the ray from the camera to it meets
//   no paper triangle nearer than two pixels of depth; otherwise not at all.
//   Nearer points are drawn over farther ones.
// All colours are linear RGB (clamped to [0, 1]); sizes are pixels at the
// render resolution.
struct StructureOverlay {
  // Per sheet triangle: replaces the paper texture and front/back colours when
  // non-empty (size must equal the triangle count).
  std::vector<Vec3> triangleColors;
  struct Line {
    Vec3 a, b;
    Vec3 color;
  };
  std::vector<Line> lines;  // e.g. rulings, region borders
  struct Point {
    Vec3 p;
    Vec3 color;
  };
  std::vector<Point> points;  // e.g. singular, junction and handle vertices
  double lineWidthPx = 2.0;
  double pointSizePx = 8.0;

  bool empty() const { return triangleColors.empty() && lines.empty() && points.empty(); }
};

// The colours of the paper's Fig. 2 (linear RGB) for a StructureOverlay.
struct StructurePalette {
  Vec3 flat{0.10, 0.50, 0.12};    // flat-region triangles (green)
  Vec3 curved{0.60, 0.10, 0.55};  // curved-region triangles (magenta)
  Vec3 ruling{0.22, 0.0, 0.20};   // rulings (darker magenta)
  Vec3 border{0.02, 0.02, 0.02};  // region borders
  Vec3 singular{0.90, 0.0, 0.0};  // singular vertices (red)
  Vec3 junction{1.0, 0.80, 0.0};  // junction vertices (yellow)
  Vec3 handle{0.0, 0.0, 0.0};     // handles (black)
};

struct RenderScene {
  Camera camera;
  std::vector<Light> lights;
  Ground ground;
  PaperLook paper;
  Vec3 background{0.80, 0.82, 0.86};  // linear RGB
};

// A deterministic ruled-notebook texture (lines and a margin) so orientation
// and stretching are visible: off-white paper, blue horizontal rules (0.7/297
// of the height thick) every 8/297 of the height below a 30/297 header band,
// a red vertical margin line (1/210 of the width) 30/210 of the width from the
// left; lines box-filtered. Rows top to bottom, sRGB, alpha 255.
// Throws std::invalid_argument unless width, height > 0.
ImageRGBA8 makeRuledPaperTexture(int width, int height);

// --- Camera math shared by the rasteriser, the path tracer and the tests ----
// World -> camera transform (the inverse of the camera pose; the camera looks
// down its local -Z with +Y up).
Mat4 viewMatrix(const Camera& camera);
// OpenGL-style perspective projection (clip space, NDC z in [-1, 1]) with
// aspect = width / height.
Mat4 projectionMatrix(const Camera& camera);
// Where a world point lands in the image, in continuous pixel coordinates: x to
// the right, y downwards (row 0 at the top), pixel (i, j) covering
// [i, i+1) x [j, j+1). Empty when the point is not in front of the camera.
std::optional<Vec2> projectToPixel(const Camera& camera, const Vec3& world);

// Linear [0, 1] -> 8-bit sRGB (clamped), the exact piecewise sRGB curve,
// rounded to nearest. The renderer encodes the background with it.
std::uint8_t linearToSrgb8(double linear);
// 8-bit sRGB -> linear [0, 1].
double srgb8ToLinear(std::uint8_t srgb);

}  // namespace crumple::render
