#pragma once
// Private to the path tracer: what one render traces against, in float and
// relative to the sheet's bounding-box centre (the render geometry of
// render_geometry.hpp turned into Embree meshes and flat shading arrays).
#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include "crumple/core/image.hpp"
#include "crumple/mesh/tear_patches.hpp"
#include "crumple/render/view.hpp"
#include "pt_math.hpp"

namespace crumple::render::pt {

constexpr int kTileSize = 16;
constexpr int kCameraBatch = 32;          // camera rays traced together (one pixel's samples)
constexpr int kRussianRouletteDepth = 3;  // vertices before roulette starts
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr double kMinSunAngle = 1e-6;  // rad
// Keys the per-pixel sample streams apart from other users of (seed, frame).
constexpr std::uint64_t kSeedSalt = 0x50617468547261ULL;  // "PathTra"

// A double vector rounded to float.
inline V3 toV3(const Vec3& v) {
  return {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z())};
}

// What an Embree geometry is: the sheet, the ground square or a prop.
enum class GeomKind : std::uint8_t { Sheet, Ground, Prop };

// One Embree triangle geometry (indexed by its geomID).
struct MeshData {
  GeomKind kind = GeomKind::Prop;
  std::vector<V3> vertices;  // relative to the origin; one padding element for Embree's loads
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<V3> faceNormals;  // unit, counter-clockwise front; zero when degenerate
  // What Embree traces (pairIntoQuads, quad_pairs.hpp): quads (q0, q1, q2, q3)
  // that Embree splits into (q0, q1, q3) and (q2, q3, q1), each the two
  // triangles of quadTriangles (the second kNoTriangle for a lone triangle
  // drawn as (a, b, c, c)); a hit's primID is a quad (triangleHit).
  static constexpr std::uint32_t kNoTriangle = 0xFFFFFFFFu;
  std::vector<std::array<std::uint32_t, 4>> quads;
  std::vector<std::array<std::uint32_t, 2>> quadTriangles;
  V3 color;               // ground and props
  float objectId = 0.0f;  // the AOVs' object id: 1 sheet, 2 ground, 3 + k prop k
  // Motion blur: the vertices and face normals at each time step (vertices
  // padded as `vertices`); empty when the mesh is still over the shutter.
  std::vector<std::vector<V3>> steps;
  std::vector<std::vector<V3>> stepFaceNormals;
};

// The sheet's shading data per triangle (a mesh triangle, or a piece of a
// tear patch drawn instead of one).
struct SheetTri {
  std::array<V3, 3> normals;      // shading normals (front side)
  std::array<float, 6> uv;        // texture coordinates of the three corners
  std::array<float, 6> maskUv{};  // tear patches: atlas positions of the corners (texels)
  bool masked = false;            // a tear patch's piece: its mask cuts it too
  // The AOVs' labels of the sheet triangle it draws (aov_pass.hpp).
  std::uint8_t region = 0;           // 0 no regions, 1 flat, 2 curved
  std::uint8_t singularCorners = 0;  // bit k: corner k is a singular vertex (mesh triangles only)
  std::uint16_t handle = 0;          // the nearest handle in the pattern, 1-based; 0 none
};

// What the alpha-cut filters and the paper shading read.
struct SheetLook {
  const ImageRGBA8* texture = nullptr;
  const mesh::TearAtlas* tears = nullptr;
  std::vector<SheetTri> tris;
  V3 front, back;
  float transmittance = 0.0f;
  // Motion blur: the shading normals of tris at each time step (empty when
  // the sheet is still).
  std::vector<std::vector<std::array<V3, 3>>> stepNormals;
};

// A hit on a triangle: its index in MeshData::triangles and barycentrics
// (u, v) of its corners 1 and 2.
struct TriangleHit {
  std::uint32_t triangle = 0;
  float u = 0.0f, v = 0.0f;
};

// The triangle and barycentrics of Embree's hit (u, v) on quad `prim`:
// the quad's first triangle below its diagonal (u + v <= 1), else the
// second, whose corners (q2, q3, q1) weigh (u + v - 1, 1 - u, 1 - v)
// (Embree manual, RTC_GEOMETRY_TYPE_QUAD).
inline TriangleHit triangleHit(const MeshData& m, unsigned prim, float u, float v) {
  const auto& pair = m.quadTriangles[prim];
  if (u + v <= 1.0f || pair[1] == MeshData::kNoTriangle) return {pair[0], u, v};
  return {pair[1], 1.0f - u, 1.0f - v};
}

// Coordinates at barycentrics (u, v) of a triangle's three corners.
inline Vec2 interpolate(const std::array<float, 6>& c, float u, float v) {
  const float w = 1.0f - u - v;
  return {static_cast<double>(w * c[0] + u * c[2] + v * c[4]),
          static_cast<double>(w * c[1] + u * c[3] + v * c[5])};
}

// Texture coordinates at barycentrics (u, v) of a sheet triangle.
inline Vec2 sheetUv(const SheetTri& t, float u, float v) { return interpolate(t.uv, u, v); }

// A light in render units (see makeLights in scene_build.cpp).
struct LightData {
  enum class Type { Directional, Sun, Point, Area };
  Type type = Type::Directional;
  V3 dir;                    // Directional/Sun: unit vector towards the light; Area: unit normal
  V3 pos;                    // Point/Area: position (relative)
  V3 radiance;               // see makeLights
  V3 su, sv;                 // Sun: frame around dir; Area: unit edge directions
  float oneMinusCos = 0.0f;  // Sun: 1 - cos(half angle)
  float pdf = 0.0f;          // Sun: 1 / solid angle
  float halfX = 0.0f, halfY = 0.0f, area = 0.0f;  // Area
  std::uint32_t pair = 0;                         // Sun/Area: dimension pair offset within a vertex
};

// The camera in render units: a pinhole or a thin lens.
struct CameraData {
  V3 pos, right, up, forward;
  float tanX = 0.0f, tanY = 0.0f;
  float lensRadius = 0.0f, focus = 1.0f;
  float invW = 0.0f, invH = 0.0f;
};

// A shading point: position, geometric and shading normals flipped to the
// side the ray came from, albedo of that side and transmittance.
struct Surface {
  V3 p, ng, ns, albedo;
  float transmittance = 0.0f;
};

// Everything the tracing reads, built once per render (buildFrameData).
struct FrameData {
  std::vector<MeshData> meshes;  // by geomID
  SheetLook sheet;
  std::vector<LightData> lights;
  std::vector<std::uint32_t> areaLights;  // indices into lights
  std::vector<std::uint32_t> sunLights;
  V3 environment;
  bool hasEnvironment = false;
  std::uint32_t pairsPerVertex = 2;
  float epsScene = 1e-6f;
  CameraData camera;
  int maxBounces = 0;
  int spp = 1;
  Vec3 origin = Vec3::Zero();  // world position of the relative origin (the AOVs' P)
  // Motion blur: the time steps over the shutter (0: nothing moves, camera
  // rays at time 0); then each camera ray draws its time from sample pair
  // 2, and the first path vertex's pairs start at cameraPairs.
  std::size_t motionSteps = 0;
  std::uint32_t cameraPairs = 2;
};

// The offset of a ray origin off a surface at p (scene scale plus float
// precision at p).
inline float originOffset(const FrameData& f, V3 p) { return f.epsScene + 4e-6f * maxAbs(p); }

}  // namespace crumple::render::pt
