// The path tracer's integrator: unidirectional, next-event estimation for
// every light with shadow rays, BSDF sampling for the environment,
// power-heuristic MIS between light and BSDF sampling for the sun discs and
// the area lights (analytic rectangles: no Embree geometry, they cast no
// shadows and camera rays do not see them), Russian roulette after 3
// bounces. Every pixel depends only on its own Owen-scrambled Sobol streams
// (pt_sampler.hpp), so the image is the same for any thread count and tile
// order.
//
// Paper BSDF (two-sided): f = a (1 - T) / pi on the side of the incoming
// ray, a T / pi on the other side, each times the cosine with the shading
// normal flipped to that side (zero below it). The side is decided by the
// geometric normal, and ray origins are offset along it (by a distance scaled
// by the scene size) so that no light leaks through the sheet.
#include "integrator.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

#include "aov_pass.hpp"
#include "crumple/core/rng.hpp"
#include "pt_sampler.hpp"

namespace crumple::render::pt {

namespace {

// A triangle of a mesh at shutter time `time` (motion blur: between the two
// time steps around it, linearly, as Embree moves it): its corners, its
// face normal (zero when degenerate) and, for the sheet's shading normals,
// the step and the weight of the next one.
struct TriangleAt {
  V3 a, b, c, ng;
  std::size_t step = 0;
  float next = 0.0f;
};

TriangleAt triangleAt(const MeshData& m, unsigned prim, float time) {
  const auto& tri = m.triangles[prim];
  TriangleAt t;
  if (m.steps.empty()) {
    t.a = m.vertices[tri[0]];
    t.b = m.vertices[tri[1]];
    t.c = m.vertices[tri[2]];
    t.ng = m.faceNormals[prim];
    return t;
  }
  const float x = time * static_cast<float>(m.steps.size() - 1);
  t.step = std::min(static_cast<std::size_t>(std::max(x, 0.0f)), m.steps.size() - 2);
  t.next = x - static_cast<float>(t.step);
  const std::vector<V3>& s0 = m.steps[t.step];
  const std::vector<V3>& s1 = m.steps[t.step + 1];
  const float w0 = 1.0f - t.next, w1 = t.next;
  t.a = s0[tri[0]] * w0 + s1[tri[0]] * w1;
  t.b = s0[tri[1]] * w0 + s1[tri[1]] * w1;
  t.c = s0[tri[2]] * w0 + s1[tri[2]] * w1;
  const V3 n = cross(t.b - t.a, t.c - t.a);
  const float len = length(n);
  t.ng = len > 0.0f ? n * (1.0f / len) : V3{};
  return t;
}

}  // namespace

Surface makeSurface(const FrameData& f, const RTCRayHit& rh, V3 dir, float time) {
  const MeshData& m = f.meshes[rh.hit.geomID];
  const TriangleHit hit = triangleHit(m, rh.hit.primID, rh.hit.u, rh.hit.v);
  const unsigned prim = hit.triangle;
  const float u = hit.u, v = hit.v;
  const TriangleAt tri = triangleAt(m, prim, time);
  Surface s;
  s.p = tri.a + (tri.b - tri.a) * u + (tri.c - tri.a) * v;
  V3 ng = tri.ng;
  if (isBlack(ng)) {
    // Degenerate in double, hit in float: Embree's normal (any orientation).
    ng = normalize(V3{rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z});
  }
  const bool front = dot(dir, ng) < 0.0f;
  s.ng = front ? ng : -ng;
  if (m.kind == GeomKind::Sheet) {
    const SheetLook& look = f.sheet;
    const SheetTri& t = look.tris[prim];
    const float w = 1.0f - u - v;
    V3 n = t.normals[0] * w + t.normals[1] * u + t.normals[2] * v;
    if (!look.stepNormals.empty()) {
      const auto& n0 = look.stepNormals[tri.step][prim];
      const auto& n1 = look.stepNormals[tri.step + 1][prim];
      const float w1 = tri.next, w0 = 1.0f - w1;
      n = (n0[0] * w0 + n1[0] * w1) * w + (n0[1] * w0 + n1[1] * w1) * u +
          (n0[2] * w0 + n1[2] * w1) * v;
    }
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

namespace {

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
  void cameraRay(float px, float py, Sample2 lens, V3& org, V3& dir) const {
    const CameraData& c = f_.camera;
    const float x = (2.0f * px * c.invW - 1.0f) * c.tanX;
    const float y = (1.0f - 2.0f * py * c.invH) * c.tanY;
    const V3 d = c.forward + c.right * x + c.up * y;
    if (c.lensRadius > 0.0f) {
      float lx, ly;
      concentricDisk(lens.x, lens.y, lx, ly);
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
  void intersect(V3 org, V3 dir, float time, RTCRayHit& rh) {
    setRay(org, dir, time, rh);
    rtcIntersect1(scene_, &incoherent_, &rh);
  }

  // Initialises a ray from org along dir, t in [0, inf), with no hit.
  static void setRay(V3 org, V3 dir, float time, RTCRayHit& rh) {
    rh.ray.org_x = org.x;
    rh.ray.org_y = org.y;
    rh.ray.org_z = org.z;
    rh.ray.tnear = 0.0f;
    rh.ray.dir_x = dir.x;
    rh.ray.dir_y = dir.y;
    rh.ray.dir_z = dir.z;
    rh.ray.time = time;
    rh.ray.tfar = kInf;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  }

  // True when nothing blocks the segment org + t dir, t in [0, tfar].
  bool visible(V3 org, V3 dir, float tfar, float time) {
    RTCRay r;
    r.org_x = org.x;
    r.org_y = org.y;
    r.org_z = org.z;
    r.tnear = 0.0f;
    r.dir_x = dir.x;
    r.dir_y = dir.y;
    r.dir_z = dir.z;
    r.time = time;
    r.tfar = tfar;
    r.mask = 0xFFFFFFFFu;
    r.id = 0;
    r.flags = 0;
    rtcOccluded1(scene_, &incoherent_, &r);
    return r.tfar >= 0.0f;
  }

  // Radiance arriving along a camera ray whose first hit's shading point is
  // `first`, at the ray's shutter time (the whole path's): premultiplied path
  // contribution; may be non-finite, the caller checks.
  V3 radiance(const Surface& first, float time, const PixelSampler& smp) {
    V3 result{}, beta{1.0f, 1.0f, 1.0f};
    Surface s = first;
    const bool needEmissionRay =
        f_.hasEnvironment || !f_.sunLights.empty() || !f_.areaLights.empty();
    for (int k = 0;; ++k) {
      const std::uint32_t base = f_.cameraPairs + static_cast<std::uint32_t>(k) * f_.pairsPerVertex;
      const float eps = originOffset(f_, s.p);
      result += beta * directLight(s, eps, smp, base, time);

      const bool last = k >= f_.maxBounces;
      if (last && !needEmissionRay) break;
      // Sample the BSDF: reflection with probability 1 - T, else transmission.
      const Sample2 u = smp.get(base + f_.pairsPerVertex - 2);
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
        ux = minf(ux, 0x1.fffffep-1f);
      }
      float cosTheta;
      const V3 wi = cosineHemisphere(transmit ? -s.ns : s.ns, ux, u.y, cosTheta);
      const float cg = dot(wi, s.ng);
      if (transmit ? !(cg < 0.0f) : !(cg > 0.0f)) break;  // below the geometric surface
      const float pdf = (transmit ? T : 1.0f - T) * cosTheta * kInvPi;
      if (!(pdf > 0.0f)) break;
      beta *= s.albedo;  // f cos / pdf
      if (k >= kRussianRouletteDepth) {
        const float q = minf(maxComponent(beta), 1.0f);
        if (!(smp.get(base + f_.pairsPerVertex - 1).x < q)) break;
        beta *= 1.0f / q;
      }
      if (isBlack(beta)) break;

      const V3 org = s.p + (cg > 0.0f ? s.ng : -s.ng) * eps;
      RTCRayHit rh;
      intersect(org, wi, time, rh);
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
      s = makeSurface(f_, rh, wi, time);
    }
    return result;
  }

 private:
  // Next-event estimation at s for every light (pairs from `base`).
  V3 directLight(const Surface& s, float eps, const PixelSampler& smp, std::uint32_t base,
                 float time) {
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
          const Sample2 u = smp.get(base + l.pair);
          const float x = u.x * l.oneMinusCos;
          const float sinTheta = std::sqrt(maxf(x * (2.0f - x), 0.0f));
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
          const Sample2 u = smp.get(base + l.pair);
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
      if (!(tfar > 0.0f) || !visible(org, wi, tfar, time)) continue;
      sum += fcos * li * weight;
    }
    return sum;
  }

  const FrameData& f_;
  RTCScene scene_;
  RTCIntersectContext coherent_;
  RTCIntersectContext incoherent_;
};

}  // namespace

std::uint64_t renderTiles(const FrameData& f, RTCScene scene, const PathTraceSettings& settings,
                          std::atomic<int>& next, ImageRGBAF& out, AovImage* aovs) {
  Tracer tracer(f, scene);
  AovPixel aovPixel(f);
  const bool withAovs = aovs != nullptr && !settings.aovs.empty();
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
        PixelSampler smp{rng.bits(pixelIndex), 0};
        double r = 0.0, g = 0.0, b = 0.0;
        int hits = 0;
        if (withAovs) aovPixel.reset();
        // The camera rays of the pixel in batches, then their paths one by one.
        for (int s0 = 0; s0 < f.spp; s0 += kCameraBatch) {
          const int count = std::min(kCameraBatch, f.spp - s0);
          for (int i = 0; i < count; ++i) {
            smp.index = static_cast<std::uint32_t>(s0 + i);
            const Sample2 pix = smp.get(0);
            V3 org, dir;
            tracer.cameraRay(static_cast<float>(x) + pix.x, static_cast<float>(y) + pix.y,
                             lens ? smp.get(1) : Sample2{0.5f, 0.5f}, org, dir);
            // Motion blur: the ray's time in the shutter, from its own pair.
            const float time = f.motionSteps > 0 ? smp.get(2).x : 0.0f;
            Tracer::setRay(org, dir, time, batch[static_cast<std::size_t>(i)]);
          }
          tracer.intersectCoherent(batch.data(), static_cast<unsigned>(count));
          for (int i = 0; i < count; ++i) {
            const RTCRayHit& rh = batch[static_cast<std::size_t>(i)];
            if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
            ++hits;
            smp.index = static_cast<std::uint32_t>(s0 + i);
            const V3 dir{rh.ray.dir_x, rh.ray.dir_y, rh.ray.dir_z};
            // The first hit's shading point, once for the AOVs and the path.
            const Surface first = makeSurface(f, rh, dir, rh.ray.time);
            if (withAovs) aovPixel.add(rh, first);
            const V3 c = albedoPass ? first.albedo : tracer.radiance(first, rh.ray.time, smp);
            if (!isFinite(c)) {
              ++dropped;
              continue;
            }
            r += c.x;
            g += c.y;
            b += c.z;
          }
        }
        if (withAovs)
          aovPixel.store(settings.aovs, static_cast<std::size_t>(pixelIndex), f.spp, *aovs);
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

}  // namespace crumple::render::pt
