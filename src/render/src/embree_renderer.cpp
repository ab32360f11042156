// The Embree 3 path tracer (embree_renderer.hpp; radiometry and the paper
// material in view.hpp).
//
// Per render: an Embree scene of the sheet (float positions relative to the
// sheet's bounding-box centre), the ground square and the props; per-triangle
// shading data in flat arrays; the image split into 16x16 tiles pulled by the
// workers (crumple::parallelFor) from a shared counter. Every pixel depends
// only on its own Owen-scrambled Sobol streams (pt_sampler.hpp), so the image
// is the same for any thread count and tile order.
//
// Light transport: unidirectional, next-event estimation for every light with
// shadow rays, BSDF sampling for the environment, power-heuristic MIS between
// light and BSDF sampling for the sun discs and the area lights (analytic
// rectangles: no Embree geometry, they cast no shadows and camera rays do not
// see them), Russian roulette after 3 bounces.
//
// Paper BSDF (two-sided): f = a (1 - T) / pi on the side of the incoming
// ray, a T / pi on the other side, each times the cosine with the shading
// normal flipped to that side (zero below it). The side is decided by the
// geometric normal, and ray origins are offset along it (by a distance scaled
// by the scene size) so that no light leaks through the sheet.
#include "crumple/render/embree_renderer.hpp"

#include <embree3/rtcore.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "crumple/core/parallel.hpp"
#include "crumple/core/rng.hpp"
#include "pt_math.hpp"
#include "pt_sampler.hpp"

namespace crumple::render {

namespace {

using pt::kInvPi;
using pt::kPi;
using pt::V3;

constexpr int kTileSize = 16;
constexpr int kCameraBatch = 32;          // camera rays traced together (one pixel's samples)
constexpr int kRussianRouletteDepth = 3;  // vertices before roulette starts
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr double kMinSunAngle = 1e-6;  // rad
// Keys the per-pixel sample streams apart from other users of (seed, frame).
constexpr std::uint64_t kSeedSalt = 0x50617468547261ULL;  // "PathTra"

// --- Embree handles ---------------------------------------------------------

struct DeviceDeleter {
  void operator()(RTCDeviceTy* d) const { rtcReleaseDevice(d); }
};
struct SceneDeleter {
  void operator()(RTCSceneTy* s) const { rtcReleaseScene(s); }
};
struct GeometryDeleter {
  void operator()(RTCGeometryTy* g) const { rtcReleaseGeometry(g); }
};
using DevicePtr = std::unique_ptr<RTCDeviceTy, DeviceDeleter>;
using ScenePtr = std::unique_ptr<RTCSceneTy, SceneDeleter>;
using GeometryPtr = std::unique_ptr<RTCGeometryTy, GeometryDeleter>;

// Embree's error code as text.
const char* errorName(RTCError e) {
  switch (e) {
    case RTC_ERROR_NONE:
      return "no error";
    case RTC_ERROR_UNKNOWN:
      return "unknown error";
    case RTC_ERROR_INVALID_ARGUMENT:
      return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION:
      return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY:
      return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU:
      return "unsupported CPU";
    case RTC_ERROR_CANCELLED:
      return "cancelled";
  }
  return "unrecognised error";
}

V3 toV3(const Vec3& v) {
  return {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z())};
}

// --- per-render data ----------------------------------------------------------

enum class GeomKind : std::uint8_t { Sheet, Ground, Prop };

// One Embree triangle geometry (indexed by its geomID).
struct MeshData {
  GeomKind kind = GeomKind::Prop;
  std::vector<V3> vertices;  // relative to the origin; one padding element for Embree's loads
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<V3> faceNormals;  // unit, counter-clockwise front; zero when degenerate
  V3 color;                     // ground and props
};

// The sheet's shading data per triangle (a mesh triangle, or a piece of a
// tear patch drawn instead of one).
struct SheetTri {
  std::array<V3, 3> normals;      // shading normals (front side)
  std::array<float, 6> uv;        // texture coordinates of the three corners
  std::array<float, 6> maskUv{};  // tear patches: atlas positions of the corners (texels)
  bool masked = false;            // a tear patch's piece: its mask cuts it too
};

// What the alpha-cut filters and the paper shading read.
struct SheetLook {
  const ImageRGBA8* texture = nullptr;
  const mesh::TearAtlas* tears = nullptr;
  std::vector<SheetTri> tris;
  V3 front, back;
  float transmittance = 0.0f;
};

// Coordinates at barycentrics (u, v) of a triangle's three corners.
inline Vec2 interpolate(const std::array<float, 6>& c, float u, float v) {
  const float w = 1.0f - u - v;
  return {static_cast<double>(w * c[0] + u * c[2] + v * c[4]),
          static_cast<double>(w * c[1] + u * c[3] + v * c[5])};
}

// Texture coordinates at barycentrics (u, v) of a sheet triangle.
inline Vec2 sheetUv(const SheetTri& t, float u, float v) { return interpolate(t.uv, u, v); }

// Embree intersect/occluded filter: rejects sheet hits where the texture's
// bilinear alpha is below 0.5 (cut-outs) or, on a tear patch, its mask is
// (view.hpp), for every kind of ray.
void alphaCutFilter(const RTCFilterFunctionNArguments* args) {
  const auto* look = static_cast<const SheetLook*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    const unsigned prim = RTCHitN_primID(args->hit, args->N, i);
    const float u = RTCHitN_u(args->hit, args->N, i);
    const float v = RTCHitN_v(args->hit, args->N, i);
    const SheetTri& t = look->tris[prim];
    if (sampleTexture(*look->texture, sheetUv(t, u, v)).w() < 0.5 ||
        (t.masked && mesh::sampleTearMask(*look->tears, interpolate(t.maskUv, u, v)) < 0.5))
      args->valid[i] = 0;
  }
}

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
};

// --- input validation -----------------------------------------------------------

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

// True when some texel's alpha is below 0.5, i.e. the bilinear alpha can be.
bool hasCutOuts(const ImageRGBA8& tex) {
  for (std::size_t i = 3; i < tex.pixels.size(); i += 4)
    if (tex.pixels[i] < 128) return true;
  return false;
}

// Unit face normal of a float triangle computed in double (zero if degenerate).
V3 faceNormal(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = (b - a).cross(c - a);
  const double len = n.norm();
  return len > 0.0 ? toV3(n / len) : V3{};
}

// The lights in render units (relative positions, radiance per the
// conventions of view.hpp). Directional: irradiance pi*I*c at normal
// incidence; Sun: radiance I*c / sin^2(half angle) (the same irradiance at
// normal incidence); Point: radiant intensity pi*I*c; Area: radiance
// pi*I*c / area.
void makeLights(const RenderScene& scene, const Vec3& origin, FrameData& f) {
  std::vector<Light> lights = scene.lights;
  if (lights.empty()) lights.push_back(Light{});
  std::uint32_t pair = 0;
  for (const Light& l : lights) {
    LightData d;
    const Vec3 c = l.color * l.intensity;
    switch (l.kind) {
      case Light::Kind::Directional: {
        const Vec3 toLight = -l.direction.normalized();
        d.dir = toV3(toLight);
        // Discs below a microradian are delta lights (float range of the radiance).
        if (l.angle > kMinSunAngle) {
          const double half = 0.5 * l.angle;
          const double s = std::sin(half), sh = std::sin(0.5 * half);
          d.type = LightData::Type::Sun;
          d.oneMinusCos = static_cast<float>(2.0 * sh * sh);
          d.pdf = static_cast<float>(1.0 / (2.0 * std::numbers::pi * 2.0 * sh * sh));
          d.radiance = toV3(c / (s * s));
          Vec3 u = toLight.unitOrthogonal();
          d.su = toV3(u);
          d.sv = toV3(toLight.cross(u));
          d.pair = pair++;
          f.sunLights.push_back(static_cast<std::uint32_t>(f.lights.size()));
        } else {
          d.type = LightData::Type::Directional;
          d.radiance = toV3(std::numbers::pi * c);
        }
        break;
      }
      case Light::Kind::Point:
        d.type = LightData::Type::Point;
        d.pos = toV3(l.position - origin);
        d.radiance = toV3(std::numbers::pi * c);
        break;
      case Light::Kind::Area: {
        d.type = LightData::Type::Area;
        const auto [u, v] = areaLightFrame(l);
        const double area = l.size.x() * l.size.y();
        d.dir = toV3(l.direction.normalized());
        d.pos = toV3(l.position - origin);
        d.su = toV3(u);
        d.sv = toV3(v);
        d.halfX = static_cast<float>(0.5 * l.size.x());
        d.halfY = static_cast<float>(0.5 * l.size.y());
        d.area = static_cast<float>(area);
        d.radiance = toV3(std::numbers::pi * c / area);
        d.pair = pair++;
        f.areaLights.push_back(static_cast<std::uint32_t>(f.lights.size()));
        break;
      }
    }
    f.lights.push_back(d);
  }
  f.pairsPerVertex = pair + 2;  // sampled lights, BSDF, roulette
}

// --- path tracing ---------------------------------------------------------------

// The offset of a ray origin off a surface at p (scene scale plus float
// precision at p).
inline float originOffset(const FrameData& f, V3 p) { return f.epsScene + 4e-6f * pt::maxAbs(p); }

// The shading point of a hit (ray direction dir, unit).
Surface makeSurface(const FrameData& f, const RTCRayHit& rh, V3 dir) {
  const MeshData& m = f.meshes[rh.hit.geomID];
  const unsigned prim = rh.hit.primID;
  const auto& tri = m.triangles[prim];
  const float u = rh.hit.u, v = rh.hit.v;
  const V3 a = m.vertices[tri[0]], b = m.vertices[tri[1]], c = m.vertices[tri[2]];
  Surface s;
  s.p = a + (b - a) * u + (c - a) * v;
  V3 ng = m.faceNormals[prim];
  if (pt::isBlack(ng)) {
    // Degenerate in double, hit in float: Embree's normal (any orientation).
    ng = normalize(V3{rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z});
  }
  const bool front = dot(dir, ng) < 0.0f;
  s.ng = front ? ng : -ng;
  if (m.kind == GeomKind::Sheet) {
    const SheetLook& look = f.sheet;
    const SheetTri& t = look.tris[prim];
    const float w = 1.0f - u - v;
    const V3 n = t.normals[0] * w + t.normals[1] * u + t.normals[2] * v;
    const float len = length(n);
    s.ns = len > 1e-4f ? n * ((front ? 1.0f : -1.0f) / len) : s.ng;
    const Vec4 tex = sampleTexture(*look.texture, sheetUv(t, u, v));
    const V3 texel{static_cast<float>(tex.x()), static_cast<float>(tex.y()),
                   static_cast<float>(tex.z())};
    s.albedo = texel * (front ? look.front : look.back);
    s.transmittance = look.transmittance;
  } else {
    s.ns = s.ng;
    s.albedo = m.color;
    s.transmittance = 0.0f;
  }
  return s;
}

// The first hit's albedo only (the albedo pass).
V3 surfaceAlbedo(const FrameData& f, const RTCRayHit& rh, V3 dir) {
  const MeshData& m = f.meshes[rh.hit.geomID];
  if (m.kind != GeomKind::Sheet) return m.color;
  const unsigned prim = rh.hit.primID;
  V3 ng = m.faceNormals[prim];
  if (pt::isBlack(ng)) ng = V3{rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z};
  const Vec4 tex = sampleTexture(*f.sheet.texture, sheetUv(f.sheet.tris[prim], rh.hit.u, rh.hit.v));
  const V3 texel{static_cast<float>(tex.x()), static_cast<float>(tex.y()),
                 static_cast<float>(tex.z())};
  return texel * (dot(dir, ng) < 0.0f ? f.sheet.front : f.sheet.back);
}

// BSDF times cosine for the unit direction wi; pdf receives the BSDF
// sampling density of wi (the scalar factor: f cos = albedo * pdf).
inline V3 evalBsdf(const Surface& s, V3 wi, float& pdf) {
  const float cg = dot(wi, s.ng), cs = dot(wi, s.ns);
  if (cg > 0.0f && cs > 0.0f) {
    pdf = (1.0f - s.transmittance) * cs * kInvPi;
  } else if (cg < 0.0f && cs < 0.0f && s.transmittance > 0.0f) {
    pdf = -s.transmittance * cs * kInvPi;
  } else {
    pdf = 0.0f;
  }
  return s.albedo * pdf;
}

// Power heuristic weight of a strategy with density a against one with b.
inline float powerHeuristic(float a, float b) {
  const float a2 = a * a, b2 = b * b;
  return a2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
}

// Everything one worker needs to trace rays.
class Tracer {
 public:
  Tracer(const FrameData& f, RTCScene scene) : f_(f), scene_(scene) {
    rtcInitIntersectContext(&coherent_);
    coherent_.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    rtcInitIntersectContext(&incoherent_);
    incoherent_.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  }

  // The camera ray of pixel sample (px, py) with lens sample lens.
  void cameraRay(float px, float py, pt::Sample2 lens, V3& org, V3& dir) const {
    const CameraData& c = f_.camera;
    const float x = (2.0f * px * c.invW - 1.0f) * c.tanX;
    const float y = (1.0f - 2.0f * py * c.invH) * c.tanY;
    const V3 d = c.forward + c.right * x + c.up * y;
    if (c.lensRadius > 0.0f) {
      float lx, ly;
      pt::concentricDisk(lens.x, lens.y, lx, ly);
      const V3 lensOffset = c.right * (lx * c.lensRadius) + c.up * (ly * c.lensRadius);
      org = c.pos + lensOffset;
      dir = normalize(d * c.focus - lensOffset);
    } else {
      org = c.pos;
      dir = normalize(d);
    }
  }

  // Closest hits of a batch of coherent camera rays set up by setRay
  // (Embree's stream API forms packets of them).
  void intersectCoherent(RTCRayHit* rays, unsigned count) {
    rtcIntersect1M(scene_, &coherent_, rays, count, sizeof(RTCRayHit));
  }

  // Closest hit along a ray (geomID RTC_INVALID_GEOMETRY_ID on a miss).
  void intersect(V3 org, V3 dir, RTCRayHit& rh) {
    setRay(org, dir, rh);
    rtcIntersect1(scene_, &incoherent_, &rh);
  }

  // Initialises a ray from org along dir, t in [0, inf), with no hit.
  static void setRay(V3 org, V3 dir, RTCRayHit& rh) {
    rh.ray.org_x = org.x;
    rh.ray.org_y = org.y;
    rh.ray.org_z = org.z;
    rh.ray.tnear = 0.0f;
    rh.ray.dir_x = dir.x;
    rh.ray.dir_y = dir.y;
    rh.ray.dir_z = dir.z;
    rh.ray.time = 0.0f;
    rh.ray.tfar = kInf;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  }

  // True when nothing blocks the segment org + t dir, t in [0, tfar].
  bool visible(V3 org, V3 dir, float tfar) {
    RTCRay r;
    r.org_x = org.x;
    r.org_y = org.y;
    r.org_z = org.z;
    r.tnear = 0.0f;
    r.dir_x = dir.x;
    r.dir_y = dir.y;
    r.dir_z = dir.z;
    r.time = 0.0f;
    r.tfar = tfar;
    r.mask = 0xFFFFFFFFu;
    r.id = 0;
    r.flags = 0;
    rtcOccluded1(scene_, &incoherent_, &r);
    return r.tfar >= 0.0f;
  }

  // Radiance arriving along a camera ray that hit `first` (premultiplied
  // path contribution; may be non-finite, the caller checks).
  V3 radiance(const RTCRayHit& first, V3 dir, const pt::PixelSampler& smp) {
    V3 result{}, beta{1.0f, 1.0f, 1.0f};
    Surface s = makeSurface(f_, first, dir);
    const bool needEmissionRay =
        f_.hasEnvironment || !f_.sunLights.empty() || !f_.areaLights.empty();
    for (int k = 0;; ++k) {
      const std::uint32_t base = 2 + static_cast<std::uint32_t>(k) * f_.pairsPerVertex;
      const float eps = originOffset(f_, s.p);
      result += beta * directLight(s, eps, smp, base);

      const bool last = k >= f_.maxBounces;
      if (last && !needEmissionRay) break;
      // Sample the BSDF: reflection with probability 1 - T, else transmission.
      const pt::Sample2 u = smp.get(base + f_.pairsPerVertex - 2);
      const float T = s.transmittance;
      bool transmit = false;
      float ux = u.x;
      if (T > 0.0f) {
        if (ux < T) {
          transmit = true;
          ux = ux / T;
        } else {
          ux = (ux - T) / (1.0f - T);
        }
        ux = pt::minf(ux, 0x1.fffffep-1f);
      }
      float cosTheta;
      const V3 wi = pt::cosineHemisphere(transmit ? -s.ns : s.ns, ux, u.y, cosTheta);
      const float cg = dot(wi, s.ng);
      if (transmit ? !(cg < 0.0f) : !(cg > 0.0f)) break;  // below the geometric surface
      const float pdf = (transmit ? T : 1.0f - T) * cosTheta * kInvPi;
      if (!(pdf > 0.0f)) break;
      beta *= s.albedo;  // f cos / pdf
      if (k >= kRussianRouletteDepth) {
        const float q = pt::minf(maxComponent(beta), 1.0f);
        if (!(smp.get(base + f_.pairsPerVertex - 1).x < q)) break;
        beta *= 1.0f / q;
      }
      if (pt::isBlack(beta)) break;

      const V3 org = s.p + (cg > 0.0f ? s.ng : -s.ng) * eps;
      RTCRayHit rh;
      intersect(org, wi, rh);
      const bool miss = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID;
      const float tHit = miss ? kInf : rh.ray.tfar;
      // Area lights crossed before the hit (they are transparent).
      for (const std::uint32_t li : f_.areaLights) {
        const LightData& l = f_.lights[li];
        const float denom = dot(wi, l.dir);
        if (!(denom < 0.0f)) continue;  // one-sided: the ray must travel against the normal
        const float t = dot(l.pos - org, l.dir) / denom;
        if (!(t > 0.0f && t < tHit)) continue;
        const V3 h = org + wi * t - l.pos;
        if (std::fabs(dot(h, l.su)) > l.halfX || std::fabs(dot(h, l.sv)) > l.halfY) continue;
        const float lightPdf = t * t / (l.area * -denom);
        result += beta * l.radiance * powerHeuristic(pdf, lightPdf);
      }
      if (miss) {
        if (f_.hasEnvironment) result += beta * f_.environment;
        for (const std::uint32_t li : f_.sunLights) {
          const LightData& l = f_.lights[li];
          const V3 d = wi - l.dir;
          if (dot(d, d) <= 2.0f * l.oneMinusCos)
            result += beta * l.radiance * powerHeuristic(pdf, l.pdf);
        }
        break;
      }
      if (last) break;
      s = makeSurface(f_, rh, wi);
    }
    return result;
  }

 private:
  // Next-event estimation at s for every light (pairs from `base`).
  V3 directLight(const Surface& s, float eps, const pt::PixelSampler& smp, std::uint32_t base) {
    V3 sum{};
    for (const LightData& l : f_.lights) {
      V3 wi, li;
      float dist = kInf, lightPdf = 0.0f;  // lightPdf 0: a delta light (no MIS)
      switch (l.type) {
        case LightData::Type::Directional:
          wi = l.dir;
          li = l.radiance;
          break;
        case LightData::Type::Sun: {
          // Uniform in the cone: 1 - cos theta uniform in [0, 1 - cos alpha].
          const pt::Sample2 u = smp.get(base + l.pair);
          const float x = u.x * l.oneMinusCos;
          const float sinTheta = std::sqrt(pt::maxf(x * (2.0f - x), 0.0f));
          const float phi = 2.0f * kPi * u.y;
          wi = l.dir * (1.0f - x) + l.su * (sinTheta * std::cos(phi)) +
               l.sv * (sinTheta * std::sin(phi));
          li = l.radiance;
          lightPdf = l.pdf;
          break;
        }
        case LightData::Type::Point: {
          const V3 d = l.pos - s.p;
          const float d2 = dot(d, d);
          if (!(d2 > 0.0f)) continue;
          dist = std::sqrt(d2);
          wi = d * (1.0f / dist);
          li = l.radiance * (1.0f / d2);
          break;
        }
        case LightData::Type::Area: {
          // Uniform over the rectangle, converted to solid angle.
          const pt::Sample2 u = smp.get(base + l.pair);
          const V3 q = l.pos + l.su * ((2.0f * u.x - 1.0f) * l.halfX) +
                       l.sv * ((2.0f * u.y - 1.0f) * l.halfY);
          const V3 d = q - s.p;
          const float d2 = dot(d, d);
          if (!(d2 > 0.0f)) continue;
          dist = std::sqrt(d2);
          wi = d * (1.0f / dist);
          const float cosLight = -dot(wi, l.dir);
          if (!(cosLight > 0.0f)) continue;  // behind the emitter
          li = l.radiance;
          lightPdf = d2 / (l.area * cosLight);
          break;
        }
      }
      float bsdfPdf;
      const V3 fcos = evalBsdf(s, wi, bsdfPdf);
      if (!(bsdfPdf > 0.0f)) continue;
      const float weight = lightPdf > 0.0f ? powerHeuristic(lightPdf, bsdfPdf) / lightPdf : 1.0f;
      if (!(weight > 0.0f)) continue;
      const V3 org = s.p + (dot(wi, s.ng) > 0.0f ? s.ng : -s.ng) * eps;
      const float tfar = dist == kInf ? kInf : dist - 2.0f * eps;
      if (!(tfar > 0.0f) || !visible(org, wi, tfar)) continue;
      sum += fcos * li * weight;
    }
    return sum;
  }

  const FrameData& f_;
  RTCScene scene_;
  RTCIntersectContext coherent_;
  RTCIntersectContext incoherent_;
};

// Renders the tiles handed out by `next` into `out`; returns the number of
// dropped non-finite samples.
std::uint64_t renderTiles(const FrameData& f, RTCScene scene, const PathTraceSettings& settings,
                          std::atomic<int>& next, ImageRGBAF& out) {
  Tracer tracer(f, scene);
  const int w = out.width, h = out.height;
  const int tilesX = (w + kTileSize - 1) / kTileSize;
  const int tilesY = (h + kTileSize - 1) / kTileSize;
  const CounterRng rng(settings.seed ^ kSeedSalt, settings.frame, RngPurpose::Generic);
  const bool albedoPass = settings.pass == RenderPass::Albedo;
  const bool lens = f.camera.lensRadius > 0.0f;
  const double invSpp = 1.0 / f.spp;
  std::uint64_t dropped = 0;
  std::array<RTCRayHit, kCameraBatch> batch;
  for (int tile = next.fetch_add(1); tile < tilesX * tilesY; tile = next.fetch_add(1)) {
    const int x0 = (tile % tilesX) * kTileSize, y0 = (tile / tilesX) * kTileSize;
    const int x1 = std::min(w, x0 + kTileSize), y1 = std::min(h, y0 + kTileSize);
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) {
        const std::uint64_t pixelIndex = static_cast<std::uint64_t>(y) * w + x;
        pt::PixelSampler smp{rng.bits(pixelIndex), 0};
        double r = 0.0, g = 0.0, b = 0.0;
        int hits = 0;
        // The camera rays of the pixel in batches, then their paths one by one.
        for (int s0 = 0; s0 < f.spp; s0 += kCameraBatch) {
          const int count = std::min(kCameraBatch, f.spp - s0);
          for (int i = 0; i < count; ++i) {
            smp.index = static_cast<std::uint32_t>(s0 + i);
            const pt::Sample2 pix = smp.get(0);
            V3 org, dir;
            tracer.cameraRay(static_cast<float>(x) + pix.x, static_cast<float>(y) + pix.y,
                             lens ? smp.get(1) : pt::Sample2{0.5f, 0.5f}, org, dir);
            Tracer::setRay(org, dir, batch[static_cast<std::size_t>(i)]);
          }
          tracer.intersectCoherent(batch.data(), static_cast<unsigned>(count));
          for (int i = 0; i < count; ++i) {
            const RTCRayHit& rh = batch[static_cast<std::size_t>(i)];
            if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
            ++hits;
            smp.index = static_cast<std::uint32_t>(s0 + i);
            const V3 dir{rh.ray.dir_x, rh.ray.dir_y, rh.ray.dir_z};
            const V3 c = albedoPass ? surfaceAlbedo(f, rh, dir) : tracer.radiance(rh, dir, smp);
            if (!pt::isFinite(c)) {
              ++dropped;
              continue;
            }
            r += c.x;
            g += c.y;
            b += c.z;
          }
        }
        float* p = out.at(x, y);
        p[0] = static_cast<float>(r * invSpp);
        p[1] = static_cast<float>(g * invSpp);
        p[2] = static_cast<float>(b * invSpp);
        p[3] = static_cast<float>(hits * invSpp);
        // A finite float sum can still overflow when narrowed.
        for (int k = 0; k < 3; ++k)
          if (!std::isfinite(p[k])) {
            p[k] = 0.0f;
            ++dropped;
          }
      }
  }
  return dropped;
}

}  // namespace

// --- EmbreeRenderer -----------------------------------------------------------

struct EmbreeRenderer::Impl {
  std::mutex errorMutex;
  std::string lastError;
  std::uint64_t dropped = 0;
  DevicePtr device;  // last: released first, before what its error callback uses

  // Records Embree's error message (called by Embree on any thread).
  static void onError(void* user, RTCError code, const char* message) {
    auto* self = static_cast<Impl*>(user);
    const std::lock_guard<std::mutex> lock(self->errorMutex);
    self->lastError = std::string(errorName(code)) + (message ? std::string(": ") + message : "");
  }

  // Throws std::runtime_error when Embree reports an error.
  void check(const char* where) {
    const RTCError e = rtcGetDeviceError(device.get());
    if (e == RTC_ERROR_NONE) return;
    const std::lock_guard<std::mutex> lock(errorMutex);
    throw std::runtime_error(std::string("EmbreeRenderer: Embree error in ") + where + ": " +
                             (lastError.empty() ? errorName(e) : lastError));
  }

  // Attaches a triangle geometry over m's (shared) buffers to the scene.
  void attach(RTCScene scene, MeshData& m, SheetLook* filterLook) {
    GeometryPtr g(rtcNewGeometry(device.get(), RTC_GEOMETRY_TYPE_TRIANGLE));
    if (!g) check("rtcNewGeometry");
    m.vertices.push_back(V3{});  // padding: Embree may read 16 bytes at the last vertex
    rtcSetSharedGeometryBuffer(g.get(), RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                               m.vertices.data(), 0, sizeof(V3), m.vertices.size() - 1);
    rtcSetSharedGeometryBuffer(g.get(), RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                               m.triangles.data(), 0, sizeof(m.triangles[0]), m.triangles.size());
    if (filterLook != nullptr) {
      rtcSetGeometryUserData(g.get(), filterLook);
      rtcSetGeometryIntersectFilterFunction(g.get(), alphaCutFilter);
      rtcSetGeometryOccludedFilterFunction(g.get(), alphaCutFilter);
    }
    rtcCommitGeometry(g.get());
    rtcAttachGeometry(scene, g.get());
    check("geometry setup");
  }

  ImageRGBAF render(const RenderScene& scene, const mesh::SheetMesh& sheet,
                    const PathTraceSettings& settings);
};

ImageRGBAF EmbreeRenderer::Impl::render(const RenderScene& scene, const mesh::SheetMesh& sheet,
                                        const PathTraceSettings& settings) {
  validateInput(scene, sheet, settings);
  dropped = 0;

  // Relative to the sheet's bounding-box centre (float precision).
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = -lo;
  for (const Vec3& p : sheet.positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Vec3 origin = sheet.positions.empty() ? Vec3::Zero() : Vec3(0.5 * (lo + hi));
  const double sheetSize = sheet.positions.empty() ? 0.0 : (hi - lo).norm();

  FrameData f;
  f.maxBounces = settings.maxBounces;
  f.spp = settings.samplesPerPixel;
  f.epsScene = static_cast<float>(1e-5 * std::max(sheetSize, 1e-2));
  f.meshes.reserve(2 + scene.props.size());

  // The sheet.
  const ImageRGBA8& texture =
      scene.paper.texture.pixels.empty() ? defaultPaperTexture() : scene.paper.texture;
  const bool cutOuts = !scene.paper.texture.pixels.empty() && hasCutOuts(texture);
  f.sheet.texture = &texture;
  f.sheet.front = toV3(scene.paper.frontColor);
  f.sheet.back = toV3(scene.paper.backColor);
  f.sheet.transmittance = static_cast<float>(scene.paper.transmittance);
  f.sheet.tears = &scene.tears;
  const bool torn = !scene.tears.empty();
  if (!sheet.triangles.empty()) {
    MeshData m;
    m.kind = GeomKind::Sheet;
    m.vertices.reserve(sheet.positions.size() + 1);
    for (const Vec3& p : sheet.positions) m.vertices.push_back(toV3(p - origin));
    const auto normals = shadingNormals(sheet.positions, sheet.triangles, scene.paper.creaseAngle,
                                        scene.sharpVertices);
    const Vec2& ts = scene.paper.textureSize;
    // The triangles a tear patch replaces.
    std::vector<char> replaced(sheet.triangles.size(), 0);
    for (const mesh::TearPatch& p : scene.tears.patches)
      replaced[static_cast<std::size_t>(p.triangle)] = 1;
    f.sheet.tris.reserve(sheet.triangles.size());
    m.triangles.reserve(sheet.triangles.size());
    m.faceNormals.reserve(sheet.triangles.size());
    for (std::size_t t = 0; t < sheet.triangles.size(); ++t) {
      if (replaced[t]) continue;
      const auto& tri = sheet.triangles[t];
      SheetTri& st = f.sheet.tris.emplace_back();
      auto& indices = m.triangles.emplace_back();
      for (std::size_t k = 0; k < 3; ++k) {
        const auto vi = static_cast<std::size_t>(tri[k]);
        indices[k] = static_cast<std::uint32_t>(vi);
        st.normals[k] = toV3(normals[t][k]);
        const Vec2 uv = patternToUv(sheet.pattern[vi], ts);
        st.uv[2 * k] = static_cast<float>(uv.x());
        st.uv[2 * k + 1] = static_cast<float>(uv.y());
      }
      m.faceNormals.push_back(faceNormal(sheet.positions[static_cast<std::size_t>(tri[0])],
                                         sheet.positions[static_cast<std::size_t>(tri[1])],
                                         sheet.positions[static_cast<std::size_t>(tri[2])]));
    }
    // The tear patches: the triangle and its support quads, each corner its
    // own vertex, cut by the patch's mask (thesis 3.3.4, Fig. 3.25).
    for (const mesh::TearPatch& patch : scene.tears.patches) {
      const auto t = static_cast<std::size_t>(patch.triangle);
      for (const mesh::TearPatchTriangle& piece : mesh::tearPatchTriangles(patch, sheet)) {
        SheetTri& st = f.sheet.tris.emplace_back();
        st.masked = true;
        auto& indices = m.triangles.emplace_back();
        for (std::size_t k = 0; k < 3; ++k) {
          const mesh::TearPatchVertex& pv = piece[k];
          indices[k] = static_cast<std::uint32_t>(m.vertices.size());
          m.vertices.push_back(toV3(pv.position - origin));
          st.normals[k] = toV3(normals[t][static_cast<std::size_t>(pv.corner)]);
          const Vec2 uv = patternToUv(pv.pattern, ts);
          st.uv[2 * k] = static_cast<float>(uv.x());
          st.uv[2 * k + 1] = static_cast<float>(uv.y());
          const Vec2 a = mesh::atlasPosition(scene.tears, patch, pv.pattern);
          st.maskUv[2 * k] = static_cast<float>(a.x());
          st.maskUv[2 * k + 1] = static_cast<float>(a.y());
        }
        m.faceNormals.push_back(
            faceNormal(piece[0].position, piece[1].position, piece[2].position));
      }
    }
    f.meshes.push_back(std::move(m));
  }
  // The ground: a square at Y = height centred under the sheet, front +Y.
  if (scene.ground.enabled) {
    MeshData m;
    m.kind = GeomKind::Ground;
    const double h = 0.5 * scene.ground.size;
    const double y = scene.ground.height - origin.y();
    m.vertices = {toV3(Vec3(-h, y, h)), toV3(Vec3(h, y, h)), toV3(Vec3(h, y, -h)),
                  toV3(Vec3(-h, y, -h))};
    m.triangles = {{0, 1, 2}, {0, 2, 3}};
    m.faceNormals = {V3{0.0f, 1.0f, 0.0f}, V3{0.0f, 1.0f, 0.0f}};
    m.color = toV3(scene.ground.color);
    f.meshes.push_back(std::move(m));
  }
  for (const PropMesh& prop : scene.props) {
    if (prop.triangles.empty()) continue;
    MeshData m;
    m.kind = GeomKind::Prop;
    m.vertices.reserve(prop.vertices.size() + 1);
    for (const Vec3& p : prop.vertices) m.vertices.push_back(toV3(p - origin));
    m.triangles.reserve(prop.triangles.size());
    m.faceNormals.reserve(prop.triangles.size());
    for (const auto& tri : prop.triangles) {
      m.triangles.push_back({static_cast<std::uint32_t>(tri[0]), static_cast<std::uint32_t>(tri[1]),
                             static_cast<std::uint32_t>(tri[2])});
      m.faceNormals.push_back(faceNormal(prop.vertices[static_cast<std::size_t>(tri[0])] - origin,
                                         prop.vertices[static_cast<std::size_t>(tri[1])] - origin,
                                         prop.vertices[static_cast<std::size_t>(tri[2])] - origin));
    }
    m.color = toV3(prop.color);
    f.meshes.push_back(std::move(m));
  }

  makeLights(scene, origin, f);
  const Vec3 env = scene.environment.color * scene.environment.intensity;
  f.environment = toV3(env);
  f.hasEnvironment = !pt::isBlack(f.environment);

  // Camera.
  const Camera& cam = scene.camera;
  const Mat3 r = cam.rotation.normalized().toRotationMatrix();
  CameraData& c = f.camera;
  c.pos = toV3(cam.position - origin);
  c.right = toV3(r.col(0));
  c.up = toV3(r.col(1));
  c.forward = toV3(-r.col(2));
  const double tanY = std::tan(0.5 * cam.yfov);
  c.tanY = static_cast<float>(tanY);
  c.tanX = static_cast<float>(tanY * cam.width / cam.height);
  c.invW = 1.0f / static_cast<float>(cam.width);
  c.invH = 1.0f / static_cast<float>(cam.height);
  c.lensRadius = static_cast<float>(cam.apertureRadius);
  c.focus = static_cast<float>(cam.focusDistance);

  // The Embree scene (declared after f: it references f's buffers).
  std::size_t triangles = 0;
  for (const MeshData& m : f.meshes) triangles += m.triangles.size();
  const ScenePtr rtcScene(rtcNewScene(device.get()));
  if (!rtcScene) check("rtcNewScene");
  rtcSetSceneFlags(rtcScene.get(), RTC_SCENE_FLAG_NONE);
  rtcSetSceneBuildQuality(rtcScene.get(),
                          triangles <= 200000 ? RTC_BUILD_QUALITY_HIGH : RTC_BUILD_QUALITY_MEDIUM);
  for (MeshData& m : f.meshes)
    attach(rtcScene.get(), m, m.kind == GeomKind::Sheet && (cutOuts || torn) ? &f.sheet : nullptr);
  rtcCommitScene(rtcScene.get());
  check("rtcCommitScene");

  ImageRGBAF out(cam.width, cam.height);
  const int tiles =
      ((cam.width + kTileSize - 1) / kTileSize) * ((cam.height + kTileSize - 1) / kTileSize);
  const int workers = std::max(1, std::min(threadCount(), tiles));
  std::atomic<int> next{0};
  std::vector<std::uint64_t> droppedBy(static_cast<std::size_t>(workers), 0);
  parallelFor(
      static_cast<std::size_t>(workers),
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
          droppedBy[i] = renderTiles(f, rtcScene.get(), settings, next, out);
      },
      1);
  for (const std::uint64_t d : droppedBy) dropped += d;
  return out;
}

EmbreeRenderer::EmbreeRenderer() : impl_(std::make_unique<Impl>()) {
  // Embree's own (TBB) threads build the BVH: as many as crumple may use, so
  // that `--threads 1` on a farm node keeps to one core.
  const std::string config = "threads=" + std::to_string(threadCount());
  impl_->device.reset(rtcNewDevice(config.c_str()));
  if (!impl_->device)
    throw std::runtime_error(std::string("EmbreeRenderer: rtcNewDevice failed: ") +
                             errorName(rtcGetDeviceError(nullptr)));
  rtcSetDeviceErrorFunction(impl_->device.get(), &Impl::onError, impl_.get());
}

EmbreeRenderer::~EmbreeRenderer() = default;

ImageRGBAF EmbreeRenderer::render(const RenderScene& scene, const mesh::SheetMesh& sheet,
                                  const PathTraceSettings& settings) {
  return impl_->render(scene, sheet, settings);
}

std::uint64_t EmbreeRenderer::droppedSamples() const { return impl_->dropped; }

ImageRGBA8 toSrgb8(const ImageRGBAF& image, const Vec3& background) {
  ImageRGBA8 out(image.width, image.height);
  const std::uint8_t bg[3] = {linearToSrgb8(background.x()), linearToSrgb8(background.y()),
                              linearToSrgb8(background.z())};
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const float* p = image.at(x, y);
      std::uint8_t* q = out.at(x, y);
      const double a = std::isfinite(p[3]) ? std::clamp(static_cast<double>(p[3]), 0.0, 1.0) : 0.0;
      const auto alpha = static_cast<std::uint8_t>(std::lround(a * 255.0));
      if (alpha > 0) {
        for (int k = 0; k < 3; ++k) q[k] = linearToSrgb8(p[k] / a);
        q[3] = alpha;
      } else {  // also an alpha too small for 8 bits
        for (int k = 0; k < 3; ++k) q[k] = bg[k];
        q[3] = 0;
      }
    }
  return out;
}

}  // namespace crumple::render
