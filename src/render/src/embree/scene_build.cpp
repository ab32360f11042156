#include "scene_build.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <stdexcept>
#include <utility>

#include "aov_pass.hpp"
#include "crumple/core/parallel.hpp"
#include "quad_pairs.hpp"

namespace crumple::render::pt {

namespace {

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

// Embree intersect/occluded filter: rejects sheet hits where the texture's
// bilinear alpha is below 0.5 (cut-outs) or, on a tear patch, its mask is
// (view.hpp), for every kind of ray. The user data is the FrameData.
void alphaCutFilter(const RTCFilterFunctionNArguments* args) {
  const auto* f = static_cast<const FrameData*>(args->geometryUserPtr);
  const SheetLook& look = f->sheet;
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    const MeshData& m = f->meshes[RTCHitN_geomID(args->hit, args->N, i)];
    const TriangleHit h =
        triangleHit(m, RTCHitN_primID(args->hit, args->N, i), RTCHitN_u(args->hit, args->N, i),
                    RTCHitN_v(args->hit, args->N, i));
    const SheetTri& t = look.tris[h.triangle];
    if (sampleTexture(*look.texture, sheetUv(t, h.u, h.v)).w() < 0.5 ||
        (t.masked && mesh::sampleTearMask(*look.tears, interpolate(t.maskUv, h.u, h.v)) < 0.5))
      args->valid[i] = 0;
  }
}

// The lights in render units (relative positions, radiance per the
// conventions of view.hpp). Directional: irradiance pi*I*c at normal
// incidence; Sun: radiance I*c / sin^2(half angle) (the same irradiance at
// normal incidence); Point: radiant intensity pi*I*c; Area: radiance
// pi*I*c / area.
// `lights` are the render geometry's (relative positions, never empty).
void makeLights(const std::vector<Light>& lights, FrameData& f) {
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
        d.pos = toV3(l.position);
        d.radiance = toV3(std::numbers::pi * c);
        break;
      case Light::Kind::Area: {
        d.type = LightData::Type::Area;
        const auto [u, v] = areaLightFrame(l);
        const double area = l.size.x() * l.size.y();
        d.dir = toV3(l.direction.normalized());
        d.pos = toV3(l.position);
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

// The sheet's Embree mesh and shading data: the triangles drawn as they are
// (sharing the sheet's vertices), then the tear patches' pieces (each corner
// its own vertex, cut by the patch's mask; thesis 3.3.4, Fig. 3.25).
MeshData sheetMesh(const mesh::SheetMesh& sheet, const detail::RenderGeometry& g, SheetLook& look) {
  MeshData m;
  m.kind = GeomKind::Sheet;
  m.vertices.reserve(g.positions.size() + 1);
  for (const detail::Float3& p : g.positions) m.vertices.push_back(V3{p[0], p[1], p[2]});
  look.tris.reserve(sheet.triangles.size());
  m.triangles.reserve(sheet.triangles.size());
  m.faceNormals.reserve(sheet.triangles.size());
  for (const std::size_t t : g.drawnTriangles) {
    const auto& tri = sheet.triangles[t];
    SheetTri& st = look.tris.emplace_back();
    auto& indices = m.triangles.emplace_back();
    for (std::size_t k = 0; k < 3; ++k) {
      const auto vi = static_cast<std::size_t>(tri[k]);
      indices[k] = static_cast<std::uint32_t>(vi);
      st.normals[k] = toV3(g.cornerNormals[t][k]);
      st.uv[2 * k] = g.uvs[vi][0];
      st.uv[2 * k + 1] = g.uvs[vi][1];
    }
    m.faceNormals.push_back(toV3(g.faceNormals[t]));
  }
  for (const detail::PatchPiece& piece : g.patchPieces) {
    SheetTri& st = look.tris.emplace_back();
    st.masked = true;
    auto& indices = m.triangles.emplace_back();
    for (std::size_t k = 0; k < 3; ++k) {
      const detail::PatchCorner& c = piece.corners[k];
      indices[k] = static_cast<std::uint32_t>(m.vertices.size());
      m.vertices.push_back(V3{c.position[0], c.position[1], c.position[2]});
      st.normals[k] = V3{c.normal[0], c.normal[1], c.normal[2]};
      st.uv[2 * k] = c.uv[0];
      st.uv[2 * k + 1] = c.uv[1];
      st.maskUv[2 * k] = static_cast<float>(c.atlas.x());
      st.maskUv[2 * k + 1] = static_cast<float>(c.atlas.y());
    }
    m.faceNormals.push_back(toV3(piece.faceNormal));
  }
  return m;
}

// The AOVs' labels of the sheet's drawn triangles and tear-patch pieces, in
// look.tris order (sheetMesh's), from their sheet triangles'
// (aov_pass.hpp). A patch's pieces have other corners than their triangle:
// they take its region and handle, and no singular corners.
void labelSheetTriangles(const RenderScene& scene, const mesh::SheetMesh& sheet,
                         const detail::RenderGeometry& g, SheetLook& look) {
  const std::vector<std::uint8_t> regions = sheetTriangleRegions(sheet, scene.modelledRegions);
  const std::vector<std::uint8_t> corners = singularCorners(sheet, scene.sharpVertices);
  const std::vector<std::uint16_t> handles = nearestHandles(sheet, scene.handleVertices);
  std::size_t i = 0;
  for (const std::size_t t : g.drawnTriangles) {
    look.tris[i].region = regions[t];
    look.tris[i].singularCorners = regions[t] > 0 ? corners[t] : 0;
    look.tris[i++].handle = handles[t];
  }
  for (const detail::PatchPiece& piece : g.patchPieces) {
    look.tris[i].region = regions[piece.triangle];
    look.tris[i++].handle = handles[piece.triangle];
  }
}

// The ground square's Embree mesh (front +Y).
MeshData groundMesh(const std::array<Vec3, 4>& corners, const Vec3& color) {
  MeshData m;
  m.kind = GeomKind::Ground;
  m.vertices = {toV3(corners[0]), toV3(corners[1]), toV3(corners[2]), toV3(corners[3])};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  m.faceNormals = {V3{0.0f, 1.0f, 0.0f}, V3{0.0f, 1.0f, 0.0f}};
  m.color = toV3(color);
  return m;
}

// A prop's Embree mesh (flat face normals).
MeshData propMesh(const detail::PropGeometry& prop) {
  MeshData m;
  m.kind = GeomKind::Prop;
  m.vertices.reserve(prop.vertices.size() + 1);
  for (const detail::Float3& p : prop.vertices) m.vertices.push_back(V3{p[0], p[1], p[2]});
  m.triangles.reserve(prop.mesh->triangles.size());
  m.faceNormals.reserve(prop.mesh->triangles.size());
  for (std::size_t i = 0; i < prop.mesh->triangles.size(); ++i) {
    const auto& tri = prop.mesh->triangles[i];
    m.triangles.push_back({static_cast<std::uint32_t>(tri[0]), static_cast<std::uint32_t>(tri[1]),
                           static_cast<std::uint32_t>(tri[2])});
    const detail::Float3& n = prop.faceNormals[i];
    m.faceNormals.push_back(V3{n[0], n[1], n[2]});
  }
  m.color = toV3(prop.mesh->color);
  return m;
}

// The camera in render units (relative position, float frame).
CameraData makeCamera(const Camera& cam) {
  const Mat3 r = cam.rotation.normalized().toRotationMatrix();
  CameraData c;
  c.pos = toV3(cam.position);
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
  return c;
}

// Attaches a quad geometry over m's (shared) buffers to the scene, with
// the alpha-cut filter reading `filterFrame` when given.
void attach(EmbreeDevice& device, RTCScene scene, MeshData& m, FrameData* filterFrame) {
  const std::unique_ptr<RTCGeometryTy, decltype(&rtcReleaseGeometry)> g(
      rtcNewGeometry(device.get(), RTC_GEOMETRY_TYPE_QUAD), &rtcReleaseGeometry);
  if (!g) device.check("rtcNewGeometry");
  m.vertices.push_back(V3{});  // padding: Embree may read 16 bytes at the last vertex
  if (m.steps.empty()) {
    rtcSetSharedGeometryBuffer(g.get(), RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                               m.vertices.data(), 0, sizeof(V3), m.vertices.size() - 1);
  } else {
    // Multi-segment motion blur: one vertex buffer per time step over [0, 1].
    rtcSetGeometryTimeStepCount(g.get(), static_cast<unsigned>(m.steps.size()));
    for (std::size_t s = 0; s < m.steps.size(); ++s) {
      std::vector<V3>& step = m.steps[s];
      step.push_back(V3{});
      rtcSetSharedGeometryBuffer(g.get(), RTC_BUFFER_TYPE_VERTEX, static_cast<unsigned>(s),
                                 RTC_FORMAT_FLOAT3, step.data(), 0, sizeof(V3), step.size() - 1);
    }
  }
  rtcSetSharedGeometryBuffer(g.get(), RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT4, m.quads.data(), 0,
                             sizeof(m.quads[0]), m.quads.size());
  if (filterFrame != nullptr) {
    rtcSetGeometryUserData(g.get(), filterFrame);
    rtcSetGeometryIntersectFilterFunction(g.get(), alphaCutFilter);
    rtcSetGeometryOccludedFilterFunction(g.get(), alphaCutFilter);
  }
  rtcCommitGeometry(g.get());
  rtcAttachGeometry(scene, g.get());
  device.check("geometry setup");
}

// Motion blur: the sheet's and the moving props' vertices, face normals and
// (the sheet's) shading normals at every time step of the shutter, about
// the frame's origin (buildStepGeometry). meshOfProp[k]: the index in
// f.meshes of prop k's mesh, -1 when it has none.
void addMotionSteps(const RenderScene& scene, const mesh::SheetMesh& sheet,
                    const detail::RenderGeometry& g, const std::vector<int>& meshOfProp,
                    FrameData& f) {
  f.motionSteps = scene.motionSteps();
  f.cameraPairs = 3;
  for (std::size_t s = 0; s < f.motionSteps; ++s) {
    const detail::RenderGeometry gs = detail::buildStepGeometry(scene, sheet, true, g, s);
    if (!scene.sheetMotion.empty() && !sheet.triangles.empty()) {
      SheetLook look;
      MeshData m = sheetMesh(sheet, gs, look);
      MeshData& data = f.meshes.front();  // the sheet's, first when it has triangles
      data.steps.push_back(std::move(m.vertices));
      data.stepFaceNormals.push_back(std::move(m.faceNormals));
      auto& normals = f.sheet.stepNormals.emplace_back();
      normals.reserve(look.tris.size());
      for (const SheetTri& t : look.tris) normals.push_back(t.normals);
    }
    for (std::size_t k = 0; k < scene.props.size(); ++k) {
      if (meshOfProp[k] < 0 || scene.props[k].motion.empty()) continue;
      MeshData m = propMesh(gs.props[k]);
      MeshData& data = f.meshes[static_cast<std::size_t>(meshOfProp[k])];
      data.steps.push_back(std::move(m.vertices));
      data.stepFaceNormals.push_back(std::move(m.faceNormals));
    }
  }
}

}  // namespace

EmbreeDevice::EmbreeDevice() {
  // Embree's own (TBB) threads build the BVH: as many as crumple may use, so
  // that `--threads 1` on a farm node keeps to one core.
  const std::string config = "threads=" + std::to_string(threadCount());
  device_.reset(rtcNewDevice(config.c_str()));
  if (!device_)
    throw std::runtime_error(std::string("EmbreeRenderer: rtcNewDevice failed: ") +
                             errorName(rtcGetDeviceError(nullptr)));
  rtcSetDeviceErrorFunction(device_.get(), &EmbreeDevice::onError, this);
}

void EmbreeDevice::onError(void* user, RTCError code, const char* message) {
  auto* self = static_cast<EmbreeDevice*>(user);
  const std::lock_guard<std::mutex> lock(self->errorMutex_);
  self->lastError_ = std::string(errorName(code)) + (message ? std::string(": ") + message : "");
}

void EmbreeDevice::check(const char* where) {
  const RTCError e = rtcGetDeviceError(device_.get());
  if (e == RTC_ERROR_NONE) return;
  const std::lock_guard<std::mutex> lock(errorMutex_);
  throw std::runtime_error(std::string("EmbreeRenderer: Embree error in ") + where + ": " +
                           (lastError_.empty() ? errorName(e) : lastError_));
}

FrameData buildFrameData(const RenderScene& scene, const mesh::SheetMesh& sheet,
                         const detail::RenderGeometry& g, const PathTraceSettings& settings) {
  FrameData f;
  f.maxBounces = settings.maxBounces;
  f.spp = settings.samplesPerPixel;
  f.epsScene = static_cast<float>(1e-5 * std::max(g.sheetSize, 1e-2));
  f.meshes.reserve(2 + scene.props.size());

  f.sheet.texture =
      scene.paper.texture.pixels.empty() ? &defaultPaperTexture() : &scene.paper.texture;
  f.sheet.front = toV3(scene.paper.frontColor);
  f.sheet.back = toV3(scene.paper.backColor);
  f.sheet.transmittance = static_cast<float>(scene.paper.transmittance);
  f.sheet.tears = &scene.tears;
  if (!sheet.triangles.empty()) {
    f.meshes.push_back(sheetMesh(sheet, g, f.sheet));
    f.meshes.back().objectId = 1.0f;
    if (!settings.aovs.empty()) labelSheetTriangles(scene, sheet, g, f.sheet);
  }
  if (g.ground) {
    f.meshes.push_back(groundMesh(*g.ground, scene.ground.color));
    f.meshes.back().objectId = 2.0f;
  }
  std::vector<int> propMeshes(g.props.size(), -1);
  for (std::size_t k = 0; k < g.props.size(); ++k)
    if (!g.props[k].mesh->triangles.empty()) {
      propMeshes[k] = static_cast<int>(f.meshes.size());
      f.meshes.push_back(propMesh(g.props[k]));
      f.meshes.back().objectId = static_cast<float>(3 + k);
    }
  f.origin = g.origin;
  if (scene.motionSteps() > 0) addMotionSteps(scene, sheet, g, propMeshes, f);

  makeLights(g.lights, f);
  const Vec3 env = scene.environment.color * scene.environment.intensity;
  f.environment = toV3(env);
  f.hasEnvironment = !isBlack(f.environment);
  f.camera = makeCamera(g.camera);
  for (MeshData& m : f.meshes) pairIntoQuads(m, m.kind == GeomKind::Sheet ? &f.sheet : nullptr);
  return f;
}

ScenePtr buildScene(EmbreeDevice& device, FrameData& f, bool cutSheet) {
  std::size_t triangles = 0;
  for (const MeshData& m : f.meshes) triangles += m.triangles.size();
  ScenePtr scene(rtcNewScene(device.get()));
  if (!scene) device.check("rtcNewScene");
  rtcSetSceneFlags(scene.get(), RTC_SCENE_FLAG_NONE);
  rtcSetSceneBuildQuality(scene.get(),
                          triangles <= 200000 ? RTC_BUILD_QUALITY_HIGH : RTC_BUILD_QUALITY_MEDIUM);
  for (MeshData& m : f.meshes)
    attach(device, scene.get(), m, m.kind == GeomKind::Sheet && cutSheet ? &f : nullptr);
  rtcCommitScene(scene.get());
  device.check("rtcCommitScene");
  return scene;
}

}  // namespace crumple::render::pt
