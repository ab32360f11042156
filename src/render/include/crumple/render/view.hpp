#pragma once
// What a renderer needs to draw one frame: camera, lights, ground, the paper's
// look. Shared by the OSMesa preview and the Embree path tracer.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "crumple/core/image.hpp"
#include "crumple/core/types.hpp"
#include "crumple/mesh/tear_patches.hpp"

namespace crumple::render {

struct Camera {
  Vec3 position{0.0, 0.3, 0.6};
  Quat rotation = Quat::Identity();  // looks down local -Z, +Y up (glTF convention)
  double yfov = 0.6981317007977318;  // rad
  double znear = 0.01;               // m
  double zfar = 100.0;               // m
  int width = 640;
  int height = 480;
  // Depth of field (thin lens; the Embree path tracer only, the preview is a
  // pinhole): lens radius in m (focal length / (2 f-number)), 0 = pinhole;
  // points at focusDistance along the view axis are sharp.
  double apertureRadius = 0.0;
  double focusDistance = 1.0;  // m

  // A camera at `position` looking at `target`, `up` projecting upwards in the
  // image. An `up` parallel to the view direction is replaced by the world axis
  // least aligned with it. Throws std::invalid_argument if target == position.
  static Camera lookAt(const Vec3& position, const Vec3& target, const Vec3& up, double yfov,
                       int width, int height);
};

// Radiometry shared by both renderers (so that they show the same picture):
// a white Lambertian surface facing a light of intensity I and colour c has
// outgoing radiance I * c (irradiance pi * I * c), for
// - Directional: everywhere (times cos of the incidence angle). angle > 0 is
//   a sun disc of that angular diameter (soft shadows in the path tracer; the
//   preview treats it as a directional light);
// - Point: at distance d, divided by d^2 (radiant intensity pi * I * c);
// - Area: a one-sided rectangle centred on `position`, emitting towards
//   `direction` (its normal), size.x() along `areaU` (a unit vector
//   perpendicular to direction; see areaLightFrame) and size.y() along
//   direction x areaU; Lambertian emitter of radiance pi * I * c / area, so
//   far away it is a point light of intensity I * cos(angle to its normal).
//   The preview lights with it as such a point light at its centre.
struct Light {
  enum class Kind { Directional, Point, Area };
  Kind kind = Kind::Directional;
  Vec3 direction{-0.4, -1.0,
                 -0.3};          // Directional: the direction the light travels; Area: its normal
  Vec3 position = Vec3::Zero();  // Point, Area (centre)
  Vec3 color{1.0, 1.0, 1.0};     // linear RGB
  double intensity = 1.0;
  double angle = 0.0;   // Directional: angular diameter of the sun disc, rad (0 = delta light)
  Vec2 size{0.1, 0.1};  // Area: side lengths, m
  bool shadow = false;  // the preview's shadow map: at most one light (the key) is honoured;
                        // the path tracer shadows every light
};

// The unit vectors (u, v) spanning an area light, u x v = direction
// (normalised): u = the world axis least aligned with direction, made
// perpendicular to it.
std::pair<Vec3, Vec3> areaLightFrame(const Light& light);

// Light arriving from all directions not blocked by geometry: uniform
// radiance color * intensity (a white surface open to the whole sky shows
// exactly that). The preview adds it unoccluded (no ambient occlusion).
struct Environment {
  Vec3 color{0.80, 0.82, 0.86};  // linear RGB
  double intensity = 0.25;
};

struct Ground {
  bool enabled = false;
  double height = 0.0;  // world Y
  double size = 2.0;    // m, a square centred under the paper
  Vec3 color{0.55, 0.50, 0.45};
};

// The paper's material (two-sided, diffuse): albedo a = texture * frontColor
// on the front (3D winding counter-clockwise as in the pattern), texture *
// backColor on the back. Of the light reaching one side, a * (1 -
// transmittance) is reflected diffusely (BRDF a (1 - T) / pi) and a *
// transmittance leaves the other side diffusely (BTDF a T / pi): back-lit
// paper glows. The albedo pass shows a itself.
//
// The texture's alpha cuts the paper (tears, cut-outs): where the bilinear
// alpha at full resolution (GL_LINEAR, texel centres at (i + 0.5) / width,
// repeat wrap; sampleTexture) is below 0.5 there is no paper at all, for
// camera rays, shadows and light alike.
struct PaperLook {
  Vec3 frontColor{0.92, 0.92, 0.90};  // linear albedo multiplying the texture
  Vec3 backColor{0.92, 0.92, 0.90};
  // The printed pattern texture (sRGB colour, straight alpha), addressed by
  // pattern coordinates divided by textureSize (u, v in [0, 1] over the
  // sheet; the texture's top row at pattern y = textureSize.y). Empty = a
  // procedural ruled paper texture (makeRuledPaperTexture), fully opaque.
  ImageRGBA8 texture;
  Vec2 textureSize{0.21, 0.297};  // m covered by the texture in u and v
  // Diffuse transmittance T in [0, 1) (paperTransmittance of the thickness).
  double transmittance = 0.0;
  // Shading normals are smooth across an edge whose dihedral angle is below
  // creaseAngle and split across sharper ones and around the sharp vertices
  // (the model's singular vertices): see shadingNormals.
  double creaseAngle = 0.5235987755982988;  // rad (30 degrees)
};

// Diffuse transmittance of a sheet of the given thickness (m):
// exp(-thickness / 62 um), 0.20 at 0.1 mm (uncoated office paper transmits
// roughly a fifth of the light through, diffusely).
double paperTransmittance(double thickness);

// A static or animated prop (table, cup, ...), already placed in the world
// for this frame: an opaque two-sided diffuse triangle mesh.
struct PropMesh {
  std::string name;
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;
  Vec3 color{0.6, 0.6, 0.6};  // linear albedo
  // Motion blur (RenderScene::sheetMotion): its vertices at the shutter's
  // time steps, each as many as `vertices`; empty: still over the shutter.
  std::vector<std::vector<Vec3>> motion;
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
  Environment environment;
  Ground ground;
  PaperLook paper;
  std::vector<PropMesh> props;
  // This frame's sharp vertices of the sheet (the model's singular vertices):
  // shading normals are not smoothed around them.
  std::vector<int> sharpVertices;
  // The sheet vertex each handle holds this frame, in the scene's handle
  // order (-1: released): the handle-id AOV's partition (aov.hpp).
  std::vector<int> handleVertices;
  // True when the sheet's regions are the crumpling model's flat and curved
  // regions (the region AOV's labels); the elastic model's one region is not.
  bool modelledRegions = false;
  // This frame's tear textures (docs/RENDERING.md "Tears"; thesis 3.3.4):
  // each patch is drawn instead of its triangle, the triangle and its
  // support quads (mesh::tearPatchTriangles), and the paper is cut where the
  // patch's mask (mesh::sampleTearMask) is below 0.5 as where the texture's alpha
  // is, for camera, bounce and shadow rays. Empty: the sheet as it is. The
  // preview's structure view with triangle colours shows the mesh without
  // them.
  mesh::TearAtlas tears;
  // The colour of uncovered pixels (their alpha is 0), linear RGB.
  Vec3 background{0.80, 0.82, 0.86};
  // Motion blur, the path tracer's (docs/RENDERING.md "Motion blur"): the
  // sheet's vertex positions at K >= 2 time steps evenly spaced over the
  // shutter, from its opening to its closing, each as many as the sheet's;
  // each camera ray has its own time in the shutter, and the surfaces move
  // linearly between the steps (Embree's multi-segment motion blur). Empty:
  // the sheet is still (its own positions); with props' motion too, every
  // non-empty one has the same K. The camera, lights and ground stay put;
  // the rasteriser draws the sheet's own positions.
  std::vector<std::vector<Vec3>> sheetMotion;

  // The number of motion-blur time steps: 0 when nothing moves.
  std::size_t motionSteps() const;
};

// What a render computes: the lit picture, or the albedo of the first
// surface seen (unlit; paper texture * side colour, ground and prop colours),
// which both renderers must agree on.
enum class RenderPass { Beauty, Albedo };

// Per-corner shading normals of the sheet (3 per triangle, unit, on the front
// side): the angle-weighted average of the face normals around the vertex
// over the triangles reachable without crossing an edge whose dihedral angle
// is >= creaseAngle (or a border); the face normal itself at a sharp vertex.
// Shared by both renderers.
std::vector<std::array<Vec3, 3>> shadingNormals(const std::vector<Vec3>& positions,
                                                const std::vector<std::array<int, 3>>& triangles,
                                                double creaseAngle,
                                                const std::vector<int>& sharpVertices);

// Bilinear lookup of an sRGB8 texture as OpenGL does it with GL_LINEAR and
// GL_REPEAT at level 0 (texel centres at (i + 0.5) / width; v = 0 is the
// first row in memory, i.e. the image's top row): linear RGB (each texel
// decoded before filtering, like GL_SRGB8_ALPHA8) and alpha in [0, 1].
Vec4 sampleTexture(const ImageRGBA8& texture, const Vec2& uv);

// The checks both renderers make before drawing (std::invalid_argument
// "<who>: <what is wrong>"): a finite camera with 0 < yfov < pi, 0 < znear <
// zfar and a valid lens; finite lights (directions non-zero, sun angle in [0,
// pi), area sizes > 0), environment, ground, paper look (texture size
// consistent, transmittance in [0, 1]) and props; a sheet whose triangles
// index its finite vertices; tear patches valid for the sheet
// (mesh::validate(atlas, sheet)).
void validateRenderInput(const RenderScene& scene, const mesh::SheetMesh& sheet, const char* who);

// The paper texture when PaperLook::texture is empty: makeRuledPaperTexture
// at 1024 x 1448 (A4 proportions), made once.
const ImageRGBA8& defaultPaperTexture();

// The texture coordinates of a pattern point (the convention above).
inline Vec2 patternToUv(const Vec2& pattern, const Vec2& textureSize) {
  return {pattern.x() / textureSize.x(), 1.0 - pattern.y() / textureSize.y()};
}

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
// An 8-bit sRGB image (straight alpha) as linear floats, colour premultiplied
// by alpha when `premultiply` (OpenEXR's convention) or left straight.
ImageRGBAF decodeSrgb8(const ImageRGBA8& image, bool premultiply);

}  // namespace crumple::render
