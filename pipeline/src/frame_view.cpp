// What the renderers draw for a cached frame (shot.hpp: FrameViewBuilder),
// and the look data a cache carries so that rendering needs nothing else
// (docs/PCACHE.md "Extension sub-blocks written by crumple").
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>

#include "crumple/core/error.hpp"
#include "crumple/exporters/pcache_tear.hpp"
#include "crumple/exporters/png.hpp"
#include "crumple/pipeline/inspect.hpp"
#include "crumple/pipeline/shot.hpp"

namespace crumple::pipeline {

namespace {

static_assert(std::endian::native == std::endian::little,
              "the cache's extension blocks are written in host order, little-endian");

constexpr std::array<char, 4> kTextureTag = {'P', 'T', 'E', 'X'};
constexpr std::array<char, 4> kPropMeshTag = {'P', 'R', 'O', 'P'};
constexpr std::array<char, 4> kPropMotionTag = {'P', 'R', 'P', 'M'};

// Little-endian append / read of plain values.
class BlockWriter {
 public:
  template <typename T>
  void put(const T& v) {
    const auto* p = reinterpret_cast<const std::uint8_t*>(&v);
    bytes.insert(bytes.end(), p, p + sizeof(T));
  }
  std::vector<std::uint8_t> bytes;
};

class BlockReader {
 public:
  BlockReader(const std::vector<std::uint8_t>& bytes, std::string what)
      : bytes_(bytes), what_(std::move(what)) {}
  template <typename T>
  T get() {
    if (bytes_.size() - pos_ < sizeof(T)) throw CorruptDataError(what_ + ": truncated");
    T v;
    std::memcpy(&v, bytes_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  // A count of items of `itemBytes` each that must fit in what is left.
  std::uint32_t count(std::size_t itemBytes) {
    const auto n = get<std::uint32_t>();
    if (static_cast<std::uint64_t>(n) * itemBytes > bytes_.size() - pos_)
      throw CorruptDataError(what_ + ": count " + std::to_string(n) + " exceeds the block");
    return n;
  }
  void expectEnd() const {
    if (pos_ != bytes_.size()) throw CorruptDataError(what_ + ": trailing bytes");
  }

 private:
  const std::vector<std::uint8_t>& bytes_;
  std::string what_;
  std::size_t pos_ = 0;
};

const cache::ExtensionBlock* findBlock(const std::vector<cache::ExtensionBlock>& blocks,
                                       const std::array<char, 4>& tag) {
  for (const auto& b : blocks)
    if (b.tag == tag) return &b;
  return nullptr;
}

}  // namespace

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
    cache::ExtensionBlock b;
    b.tag = kTextureTag;
    b.data.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    // Checked now, so that a bad file is an input error before anything is written.
    try {
      (void)exporters::decodePngBytes(b.data, scene.look.texture);
    } catch (const InputError& e) {
      throw InputError(scene.file, scene.look.textureLine, "paper.texture", e.what());
    }
    blocks.push_back(std::move(b));
  }
  BlockWriter w;
  std::uint32_t meshProps = 0;
  for (const auto& p : scene.props) meshProps += p.node.empty() ? 0 : 1;
  if (meshProps > 0) {
    if (animation == nullptr)
      throw InputError(scene.file, "[[props]] mesh nodes need the animation file");
    w.put(meshProps);
    for (const auto& p : scene.props) {
      if (p.node.empty()) continue;
      const auto m = animation->mesh(p.node);
      if (!m || m->triangles.empty())
        throw InputError(scene.file, p.nodeLine, "props.node",
                         "node '" + p.node + "' holds no triangle mesh");
      w.put(static_cast<std::uint32_t>(m->vertices.size()));
      for (const Vec3& v : m->vertices)
        for (int k = 0; k < 3; ++k) w.put(v[k]);
      w.put(static_cast<std::uint32_t>(m->triangles.size()));
      for (const auto& t : m->triangles)
        for (const int i : t) w.put(static_cast<std::int32_t>(i));
    }
    blocks.push_back({kPropMeshTag, std::move(w.bytes)});
  }
  return blocks;
}

std::optional<cache::ExtensionBlock> propMotionBlock(const io::SceneSpec& scene,
                                                     const io::AnimationScene* animation,
                                                     double t) {
  BlockWriter w;
  std::uint32_t n = 0;
  for (const auto& p : scene.props) n += p.node.empty() ? 0 : 1;
  if (n == 0 || animation == nullptr) return std::nullopt;
  w.put(n);
  for (const auto& p : scene.props) {
    if (p.node.empty()) continue;
    // The stored mesh is the node's world mesh at t = 0: carry it along.
    const Mat4 motion =
        animation->worldMatrix(p.node, t) * animation->worldMatrix(p.node, 0.0).inverse();
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) w.put(motion(r, c));
  }
  return cache::ExtensionBlock{kPropMotionTag, std::move(w.bytes)};
}

FrameViewBuilder::FrameViewBuilder(const io::SceneSpec& scene,
                                   const std::vector<cache::ExtensionBlock>& headerBlocks)
    : scene_(scene) {
  if (const auto* tex = findBlock(headerBlocks, kTextureTag))
    texture_ = exporters::decodePngBytes(tex->data, "the cache's paper texture");
  else
    texture_ = render::makeRuledPaperTexture(512, 512);
  for (const auto& p : scene.props)
    if (p.node.empty()) boxes_.push_back(boxProp(p));
  if (const auto* props = findBlock(headerBlocks, kPropMeshTag)) {
    BlockReader r(props->data, "the cache's prop meshes");
    const std::uint32_t n = r.count(8);
    std::vector<const io::PropSpec*> specs;
    for (const auto& p : scene.props)
      if (!p.node.empty()) specs.push_back(&p);
    if (n != specs.size())
      throw CorruptDataError("the cache holds " + std::to_string(n) + " prop meshes, its scene " +
                             std::to_string(specs.size()));
    for (std::uint32_t i = 0; i < n; ++i) {
      render::PropMesh m;
      m.name = specs[i]->name;
      m.color = specs[i]->color;
      m.vertices.resize(r.count(24));
      for (Vec3& v : m.vertices) {
        for (int k = 0; k < 3; ++k) v[k] = r.get<double>();
        if (!v.allFinite())
          throw CorruptDataError("the cache's prop meshes: a vertex of '" + m.name +
                                 "' is not finite");
      }
      m.triangles.resize(r.count(12));
      for (auto& t : m.triangles)
        for (int& k : t) {
          k = r.get<std::int32_t>();
          if (k < 0 || static_cast<std::size_t>(k) >= m.vertices.size())
            throw CorruptDataError("the cache's prop meshes: vertex index out of range");
        }
      meshPropsAtRest_.push_back(std::move(m));
    }
    r.expectEnd();
  }
}

FrameView FrameViewBuilder::build(const cache::FrameRecord& frame) const {
  FrameView fv;
  fv.scene = makeRenderScene(scene_, frame.camera);
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
    const auto* motions = findBlock(frame.extensions, kPropMotionTag);
    if (motions == nullptr)
      throw CorruptDataError("frame " + std::to_string(frame.frame) +
                             " of the cache lacks its prop motions");
    BlockReader r(motions->data, "frame " + std::to_string(frame.frame) + " prop motions");
    if (r.count(128) != meshPropsAtRest_.size())
      throw CorruptDataError("frame " + std::to_string(frame.frame) +
                             ": prop motions do not match the prop meshes");
    for (const auto& rest : meshPropsAtRest_) {
      Mat4 motion;
      for (int c = 0; c < 4; ++c)
        for (int row = 0; row < 4; ++row) motion(row, c) = r.get<double>();
      if (!motion.allFinite())
        throw CorruptDataError("frame " + std::to_string(frame.frame) + ": the motion of prop '" +
                               rest.name + "' is not finite");
      render::PropMesh m = rest;
      for (Vec3& v : m.vertices) v = (motion * v.homogeneous()).head<3>();
      fv.scene.props.push_back(std::move(m));
    }
    r.expectEnd();
  }
  fv.scene.sharpVertices = frame.singularVertices;
  fv.sheet = sheetOfFrame(frame);
  // The frame's tear textures (docs/PCACHE.md "TEAR"), checked against its mesh.
  if (auto tears = cache::decodeTearAtlas(frame.extensions)) {
    if (const std::string problem = mesh::validate(*tears, fv.sheet); !problem.empty())
      throw CorruptDataError("frame " + std::to_string(frame.frame) +
                             " of the cache: TEAR sub-block: " + problem);
    fv.scene.tears = std::move(*tears);
  }
  return fv;
}

}  // namespace crumple::pipeline
