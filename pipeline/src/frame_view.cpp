// What the renderers draw for a cached frame (shot.hpp: FrameViewBuilder),
// and the look data a cache carries so that rendering needs nothing else
// (docs/PCACHE.md "Extension sub-blocks written by crumple").
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>

#include "crumple/cache/pcache_developable.hpp"
#include "crumple/cache/pcache_look.hpp"
#include "crumple/cache/pcache_tear.hpp"
#include "crumple/core/error.hpp"
#include "crumple/exporters/png.hpp"
#include "crumple/pipeline/inspect.hpp"
#include "crumple/pipeline/refine.hpp"
#include "crumple/pipeline/shot.hpp"
#include "frame_motion.hpp"

namespace crumple::pipeline {

mesh::SheetMesh sheetOfFrame(const cache::FrameRecord& frame) {
  mesh::SheetMesh m;
  m.pattern = frame.pattern;
  m.positions = frame.positions;
  m.triangles = frame.triangles;
  m.regionOfTriangle = frame.regionOfTriangle;
  for (auto t : frame.regionTypes) m.regionTypes.push_back(static_cast<mesh::RegionType>(t));
  return m;
}

render::RenderScene makeRenderScene(const io::SceneSpec& scene, const cache::CameraRecord& camera) {
  render::RenderScene view;
  view.camera.position = camera.position;
  view.camera.rotation = camera.rotation;
  view.camera.yfov = camera.yfov > 0.0 ? camera.yfov : scene.camera.yfov;
  view.camera.width = scene.camera.width;
  view.camera.height = scene.camera.height;
  if (scene.camera.fStop > 0.0) {
    // Thin lens: focal length from the field of view and the sensor width.
    const double aspect = static_cast<double>(view.camera.width) / view.camera.height;
    const double focal =
        scene.camera.sensorWidth / aspect / (2.0 * std::tan(0.5 * view.camera.yfov));
    view.camera.apertureRadius = focal / (2.0 * scene.camera.fStop);
    view.camera.focusDistance = scene.camera.focusDistance > 0.0 ? scene.camera.focusDistance
                                : scene.camera.node.empty()
                                    ? (scene.camera.lookAt - scene.camera.position).norm()
                                    : 1.0;
  }
  for (const auto& l : scene.lights) {
    render::Light light;
    switch (l.kind) {
      case io::LightSpec::Kind::Directional:
        light.kind = render::Light::Kind::Directional;
        break;
      case io::LightSpec::Kind::Point:
        light.kind = render::Light::Kind::Point;
        break;
      case io::LightSpec::Kind::Area:
        light.kind = render::Light::Kind::Area;
        break;
    }
    light.direction = l.direction;
    light.position = l.position;
    light.color = l.color;
    light.intensity = l.intensity;
    light.angle = l.angle;
    light.size = l.size;
    light.shadow = l.shadow;
    view.lights.push_back(light);
  }
  view.environment.color = scene.environment.color;
  view.environment.intensity = scene.environment.intensity;
  view.ground.enabled = scene.ground.enabled;
  view.ground.height = scene.ground.height;
  view.ground.size = scene.ground.size;
  view.ground.color = scene.ground.color;
  view.paper.frontColor = scene.paper.frontColor;
  view.paper.backColor = scene.paper.backColor;
  view.paper.transmittance =
      scene.look.transmittance.value_or(render::paperTransmittance(scene.paper.material.thickness));
  view.paper.creaseAngle = scene.look.creaseAngle;
  return view;
}

namespace {

// An axis-aligned box as 12 outward-facing triangles.
render::PropMesh boxProp(const io::PropSpec& p) {
  render::PropMesh m;
  m.name = p.name;
  m.color = p.color;
  const Vec3 h = 0.5 * p.boxSize;
  for (int i = 0; i < 8; ++i)
    m.vertices.push_back(p.position + Vec3((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(),
                                           (i & 4) ? h.z() : -h.z()));
  m.triangles = {{0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}, {0, 1, 5}, {0, 5, 4},
                 {2, 6, 7}, {2, 7, 3}, {0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}};
  return m;
}

}  // namespace

std::vector<cache::ExtensionBlock> lookHeaderBlocks(const io::SceneSpec& scene,
                                                    const io::AnimationScene* animation) {
  std::vector<cache::ExtensionBlock> blocks;
  if (!scene.look.texture.empty()) {
    std::ifstream in(scene.look.texture, std::ios::binary);
    if (!in)
      throw InputError(scene.file, scene.look.textureLine, "paper.texture",
                       "cannot read " + scene.look.texture);
    std::vector<std::uint8_t> png(std::istreambuf_iterator<char>(in),
                                  (std::istreambuf_iterator<char>()));
    // Checked now, so that a bad file is an input error before anything is written.
    try {
      (void)exporters::decodePngBytes(png, scene.look.texture);
    } catch (const InputError& e) {
      throw InputError(scene.file, scene.look.textureLine, "paper.texture", e.what());
    }
    blocks.push_back(cache::encodePaperTexture(std::move(png)));
  }
  std::vector<cache::PropMeshRecord> meshes;
  for (const auto& p : scene.props) {
    if (p.node.empty()) continue;
    if (animation == nullptr)
      throw InputError(scene.file, "[[props]] mesh nodes need the animation file");
    const auto m = animation->mesh(p.node);
    if (!m || m->triangles.empty())
      throw InputError(scene.file, p.nodeLine, "props.node",
                       "node '" + p.node + "' holds no triangle mesh");
    meshes.push_back({m->vertices, m->triangles});
  }
  if (!meshes.empty()) blocks.push_back(cache::encodePropMeshes(meshes));
  return blocks;
}

std::optional<cache::ExtensionBlock> propMotionBlock(const io::SceneSpec& scene,
                                                     const io::AnimationScene* animation,
                                                     double t) {
  if (animation == nullptr) return std::nullopt;
  std::vector<Mat4> motions;
  for (const auto& p : scene.props) {
    if (p.node.empty()) continue;
    // The stored mesh is the node's world mesh at t = 0: carry it along.
    motions.push_back(animation->worldMatrix(p.node, t) *
                      animation->worldMatrix(p.node, 0.0).inverse());
  }
  if (motions.empty()) return std::nullopt;
  return cache::encodePropMotions(motions);
}

namespace {

// The pixel size along the camera's view axis (mesh::ScreenMetric).
mesh::ScreenMetric screenMetric(const render::Camera& camera) {
  mesh::ScreenMetric m;
  m.eye = camera.position;
  m.forward = camera.rotation * Vec3(0.0, 0.0, -1.0);
  m.pixelAngle = 2.0 * std::tan(0.5 * camera.yfov) / camera.height;
  m.znear = camera.znear;
  return m;
}

}  // namespace

FrameViewBuilder::FrameViewBuilder(const io::SceneSpec& scene,
                                   const std::vector<cache::ExtensionBlock>& headerBlocks,
                                   const mesh::RefineOptions& refine)
    : scene_(scene), refine_(refine) {
  if (const auto* png = cache::findPaperTexture(headerBlocks))
    texture_ = exporters::decodePngBytes(*png, "the cache's paper texture");
  else
    texture_ = render::makeRuledPaperTexture(512, 512);
  for (const auto& p : scene.props)
    if (p.node.empty()) boxes_.push_back(boxProp(p));
  if (auto meshes = cache::decodePropMeshes(headerBlocks)) {
    std::vector<const io::PropSpec*> specs;
    for (const auto& p : scene.props)
      if (!p.node.empty()) specs.push_back(&p);
    if (meshes->size() != specs.size())
      throw CorruptDataError("the cache holds " + std::to_string(meshes->size()) +
                             " prop meshes, its scene " + std::to_string(specs.size()));
    for (std::size_t i = 0; i < specs.size(); ++i) {
      render::PropMesh m;
      m.name = specs[i]->name;
      m.color = specs[i]->color;
      m.vertices = std::move((*meshes)[i].vertices);
      m.triangles = std::move((*meshes)[i].triangles);
      meshPropsAtRest_.push_back(std::move(m));
    }
  }
  shutter_ = cache::decodeShutter(headerBlocks).value_or(cache::Shutter{});
}

FrameView FrameViewBuilder::build(const cache::FrameRecord& source) const {
  FrameView fv;
  fv.scene = makeRenderScene(scene_, source.camera);
  // The crumpling model's curved regions refined (refine.hpp), Auto on this
  // frame's camera.
  std::optional<cache::FrameRecord> refinedFrame;
  const bool developable = std::ranges::any_of(
      source.extensions, [](const auto& b) { return b.tag == cache::kDevelopableTag; });
  if (refine_.mode != mesh::RefineMode::Off && developable) {
    refinedFrame = source;
    mesh::RefineOptions o = refine_;
    if (o.mode == mesh::RefineMode::Auto && !o.screen) o.screen = screenMetric(fv.scene.camera);
    fv.refined = refineFrame(*refinedFrame, o);
  }
  const cache::FrameRecord& frame = refinedFrame ? *refinedFrame : source;
  fv.scene.paper.texture = texture_;
  if (scene_.look.textureSize.x() > 0.0) {
    fv.scene.paper.textureSize = scene_.look.textureSize;
  } else {
    // The texture spans the pattern's bounding box.
    Vec2 lo = Vec2::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (const auto& p : frame.pattern) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    fv.scene.paper.textureSize = (hi - lo).cwiseMax(Vec2::Constant(1e-6));
  }
  fv.scene.props = boxes_;
  if (!meshPropsAtRest_.empty()) {
    const auto motions = cache::decodePropMotions(frame.extensions);
    if (!motions)
      throw CorruptDataError("frame " + std::to_string(frame.frame) +
                             " of the cache lacks its prop motions");
    if (motions->size() != meshPropsAtRest_.size())
      throw CorruptDataError("frame " + std::to_string(frame.frame) +
                             ": prop motions do not match the prop meshes");
    for (std::size_t i = 0; i < motions->size(); ++i) {
      render::PropMesh m = meshPropsAtRest_[i];
      for (Vec3& v : m.vertices) v = ((*motions)[i] * v.homogeneous()).head<3>();
      fv.scene.props.push_back(std::move(m));
    }
  }
  fv.scene.sharpVertices = frame.singularVertices;
  fv.scene.handleVertices = frame.handleVertices;
  fv.scene.modelledRegions = scene_.model.type == io::ModelSpec::Type::Hybrid;
  fv.sheet = sheetOfFrame(frame);
  // The frame's tear textures (docs/PCACHE.md "TEAR"), checked against its mesh.
  if (auto tears = cache::decodeTearAtlas(frame.extensions)) {
    if (const std::string problem = mesh::validate(*tears, fv.sheet); !problem.empty())
      throw CorruptDataError("frame " + std::to_string(frame.frame) +
                             " of the cache: TEAR sub-block: " + problem);
    fv.scene.tears = std::move(*tears);
  }
  if (shutter_.on())
    detail::addShutterMotion(fv.scene, fv.sheet, frame, shutter_, scene_.fps, boxes_.size(),
                             meshPropsAtRest_);
  return fv;
}

}  // namespace crumple::pipeline
