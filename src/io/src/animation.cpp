// Keyframed node animation through assimp 5.2 (glTF 2.0, FBX, COLLADA),
// normalised into crumple's world: Y-up, metres, seconds. docs/SCENE.md
// ("Animation files") records what each assimp importer does and what is
// corrected here.
#include "crumple/io/animation.hpp"

#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>  // also aiMetadata (metadata.h is not self-contained)

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <unordered_map>

#include "crumple/core/error.hpp"
#include "fbx_takes.hpp"
#include "import_probe.hpp"

namespace crumple::io {

namespace {

enum class Format { Gltf, Fbx, Collada, Other };

Mat4 toMat4(const aiMatrix4x4& m) {
  Mat4 r;
  r << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3,
      m.d4;
  return r;
}

Vec3 toVec3(const aiVector3D& v) { return {v.x, v.y, v.z}; }
Quat toQuat(const aiQuaternion& q) { return Quat(q.w, q.x, q.y, q.z); }

bool finite(const Vec3& v) { return v.allFinite(); }
bool finite(const Quat& q) { return q.coeffs().allFinite(); }

Mat4 compose(const Vec3& t, const Quat& r, const Vec3& s) {
  Mat4 m = Mat4::Identity();
  m.topLeftCorner<3, 3>() = r.toRotationMatrix() * s.asDiagonal();
  m.topRightCorner<3, 1>() = t;
  return m;
}

std::string fmt(double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

std::optional<double> metaNumber(const aiMetadata* md, const char* key) {
  if (!md) return std::nullopt;
  for (unsigned i = 0; i < md->mNumProperties; ++i) {
    if (std::string_view(md->mKeys[i].C_Str()) != key) continue;
    const aiMetadataEntry& e = md->mValues[i];
    if (!e.mData) return std::nullopt;
    switch (e.mType) {
      case AI_BOOL:
        return *static_cast<const bool*>(e.mData) ? 1.0 : 0.0;
      case AI_INT32:
        return *static_cast<const std::int32_t*>(e.mData);
      case AI_UINT64:
        return static_cast<double>(*static_cast<const std::uint64_t*>(e.mData));
      case AI_FLOAT:
        return *static_cast<const float*>(e.mData);
      case AI_DOUBLE:
        return *static_cast<const double*>(e.mData);
      default:
        return std::nullopt;
    }
  }
  return std::nullopt;
}

std::string metaString(const aiMetadata* md, const char* key) {
  if (!md) return {};
  aiString s;
  if (md->Get(key, s)) return s.C_Str();
  return {};
}

Format detectFormat(const aiScene* scene, const std::string& path) {
  // Importer::ReadFile records the importer's name ("glTF2 Importer",
  // "Autodesk FBX Importer", "Collada Importer") unless the importer set one.
  const std::string name = metaString(scene->mMetaData, "SourceAsset_Format");
  if (name.find("glTF") != std::string::npos) return Format::Gltf;
  if (name.find("FBX") != std::string::npos) return Format::Fbx;
  if (name.find("Collada") != std::string::npos) return Format::Collada;
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  if (ext == ".gltf" || ext == ".glb") return Format::Gltf;
  if (ext == ".fbx") return Format::Fbx;
  if (ext == ".dae") return Format::Collada;
  return Format::Other;
}

// assimp 5.2.5's FBX importer neither scales nor rotates: it only records the
// FBX GlobalSettings in the scene metadata. Build the change of basis here:
// crumple X = Coord axis, Y = Up axis, Z = Front axis (each with its sign),
// scaled by UnitScaleFactor centimetres per file unit.
Mat4 fbxFileToWorld(const aiScene* scene, const std::string& file) {
  const aiMetadata* md = scene->mMetaData;
  auto get = [&](const char* key, double def) { return metaNumber(md, key).value_or(def); };
  const int up = static_cast<int>(get("UpAxis", 1)),
            upSign = static_cast<int>(get("UpAxisSign", 1));
  const int front = static_cast<int>(get("FrontAxis", 2));
  const int frontSign = static_cast<int>(get("FrontAxisSign", 1));
  const int coord = static_cast<int>(get("CoordAxis", 0));
  const int coordSign = static_cast<int>(get("CoordAxisSign", 1));
  const double unit = get("UnitScaleFactor", 1.0);
  const std::string axes = "UpAxis " + std::to_string(up) + " (sign " + std::to_string(upSign) +
                           "), FrontAxis " + std::to_string(front) + " (sign " +
                           std::to_string(frontSign) + "), CoordAxis " + std::to_string(coord) +
                           " (sign " + std::to_string(coordSign) + ")";
  auto axisOk = [](int a) { return a >= 0 && a <= 2; };
  auto signOk = [](int s) { return s == 1 || s == -1; };
  if (!axisOk(up) || !axisOk(front) || !axisOk(coord) || up == front || up == coord ||
      front == coord || !signOk(upSign) || !signOk(frontSign) || !signOk(coordSign)) {
    throw InputError(file, "invalid FBX axis system: " + axes);
  }
  if (!(std::isfinite(unit) && unit > 0.0)) {
    throw InputError(file, "invalid FBX UnitScaleFactor " + fmt(unit));
  }
  Mat3 b = Mat3::Zero();
  b(0, coord) = coordSign;
  b(1, up) = upSign;
  b(2, front) = frontSign;
  if (b.determinant() < 0.0) {
    throw InputError(file, "left-handed FBX axis system (" + axes +
                               ") is not supported; export with a right-handed system");
  }
  Mat4 c = Mat4::Identity();
  c.topLeftCorner<3, 3>() = 0.01 * unit * b;
  return c;
}

}  // namespace

double ticksToSeconds(double ticks, double ticksPerSecond) {
  return ticks / (ticksPerSecond > 0.0 ? ticksPerSecond : kFallbackTicksPerSecond);
}

namespace {
// The two keys around t and the blend between them, clamped at both ends
// (lo == hi, s == 0 outside the keyed span); n must be > 0.
struct KeyBracket {
  std::size_t lo = 0, hi = 0;
  double s = 0.0;
};
KeyBracket bracket(const std::vector<double>& times, std::size_t n, double t) {
  if (n == 1 || !(t > times.front())) return {0, 0, 0.0};
  if (t >= times[n - 1]) return {n - 1, n - 1, 0.0};
  const auto hi = static_cast<std::size_t>(
      std::upper_bound(times.begin(), times.begin() + static_cast<std::ptrdiff_t>(n), t) -
      times.begin());
  const std::size_t lo = hi - 1;
  const double dt = times[hi] - times[lo];
  if (!(dt > 0.0)) return {hi, hi, 0.0};
  return {lo, hi, (t - times[lo]) / dt};
}
}  // namespace

Vec3 samplePosition(const std::vector<double>& times, const std::vector<Vec3>& values, double t,
                    const Vec3& fallback) {
  const std::size_t n = std::min(times.size(), values.size());
  if (n == 0) return fallback;
  const auto [lo, hi, s] = bracket(times, n, t);
  return lo == hi ? values[lo] : Vec3(values[lo] + s * (values[hi] - values[lo]));
}

Quat sampleRotation(const std::vector<double>& times, const std::vector<Quat>& values, double t,
                    const Quat& fallback) {
  const std::size_t n = std::min(times.size(), values.size());
  if (n == 0) return fallback;
  const auto [lo, hi, s] = bracket(times, n, t);
  // Eigen's slerp takes the shorter arc (it flips the sign when dot < 0).
  return lo == hi ? values[lo] : Quat(values[lo].slerp(s, values[hi]).normalized());
}

struct AnimationScene::Impl {
  struct Node {
    std::string name;
    int parent = -1;
    Mat4 rest = Mat4::Identity();  // aiNode::mTransformation
    Vec3 restT = Vec3::Zero();
    Quat restR = Quat::Identity();
    Vec3 restS = Vec3::Ones();
    bool animated = false;
    NodeKeys keys;
    std::vector<unsigned> meshes;
  };
  struct Camera {
    int node = -1;
    Vec3 position = Vec3::Zero();
    Vec3 lookAt = -Vec3::UnitZ();
    Vec3 up = Vec3::UnitY();
    double hfov = 0.0;
    double aspect = 0.0;
  };

  std::string file;
  Format format = Format::Other;
  Mat4 fileToWorld = Mat4::Identity();
  std::vector<detail::FbxTake> fbxTakes;  // FBX: the takes as the file states them
  std::vector<Node> nodes;                // parents before children
  std::unordered_map<std::string, int> byName;
  std::set<std::string> duplicates;
  std::vector<ImportedMesh> meshes;  // in mesh-local coordinates
  std::vector<Camera> cameras;
  double start = 0.0;
  double end = 0.0;
  std::vector<std::string> warnings;

  [[noreturn]] void fail(const std::string& problem) const { throw InputError(file, problem); }

  int find(const std::string& name) const {
    if (duplicates.count(name)) {
      fail("node '" + name + "' is not unique in the file; rename it in the DCC tool");
    }
    const auto it = byName.find(name);
    if (it != byName.end()) return it->second;
    std::string list;
    int shown = 0;
    for (const Node& n : nodes) {
      if (n.parent < 0) continue;  // the root is rarely what the user meant
      if (shown == 20) {
        list += ", ...";
        break;
      }
      list += (shown++ ? ", " : "") + n.name;
    }
    fail("no node named '" + name + "'" + (list.empty() ? "" : " (nodes: " + list + ")"));
  }

  Mat4 local(int i, double t) const {
    const Node& n = nodes[static_cast<std::size_t>(i)];
    if (!n.animated) return n.rest;
    const NodeKeys& k = n.keys;
    return compose(samplePosition(k.positionTimes, k.positions, t, n.restT),
                   sampleRotation(k.rotationTimes, k.rotations, t, n.restR),
                   sampleScaling(k.scalingTimes, k.scalings, t, n.restS));
  }

  Mat4 world(int i, double t) const {
    Mat4 m = local(i, t);
    for (int p = nodes[static_cast<std::size_t>(i)].parent; p >= 0;
         p = nodes[static_cast<std::size_t>(p)].parent) {
      m = local(p, t) * m;
    }
    return fileToWorld * m;
  }

  void addNodes(const aiNode* node, int parent) {
    const int index = static_cast<int>(nodes.size());
    Node n;
    n.name = node->mName.C_Str();
    n.parent = parent;
    n.rest = toMat4(node->mTransformation);
    if (!n.rest.allFinite()) fail("node '" + n.name + "': non-finite transform");
    aiVector3D s, p;
    aiQuaternion r;
    node->mTransformation.Decompose(s, r, p);
    n.restT = toVec3(p);
    n.restR = toQuat(r).normalized();
    n.restS = toVec3(s);
    n.meshes.assign(node->mMeshes, node->mMeshes + node->mNumMeshes);
    if (!byName.emplace(n.name, index).second) duplicates.insert(n.name);
    nodes.push_back(std::move(n));
    for (unsigned c = 0; c < node->mNumChildren; ++c) addNodes(node->mChildren[c], index);
  }

  void addMeshes(const aiScene* scene) {
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
      const aiMesh* in = scene->mMeshes[m];
      ImportedMesh out;
      out.vertices.reserve(in->mNumVertices);
      for (unsigned v = 0; v < in->mNumVertices; ++v) {
        out.vertices.push_back(toVec3(in->mVertices[v]));
        if (!finite(out.vertices.back())) {
          fail("mesh '" + std::string(in->mName.C_Str()) + "': non-finite vertex " +
               std::to_string(v));
        }
      }
      for (unsigned f = 0; f < in->mNumFaces; ++f) {
        const aiFace& face = in->mFaces[f];
        if (face.mNumIndices != 3) continue;  // points and lines are not surface
        std::array<int, 3> tri{};
        for (int k = 0; k < 3; ++k) {
          if (face.mIndices[k] >= in->mNumVertices) {
            fail("mesh '" + std::string(in->mName.C_Str()) + "': face " + std::to_string(f) +
                 " indexes a missing vertex");
          }
          tri[static_cast<std::size_t>(k)] = static_cast<int>(face.mIndices[k]);
        }
        out.triangles.push_back(tri);
      }
      meshes.push_back(std::move(out));
    }
  }

  template <class Key, class Value, class Convert>
  void readKeys(const Key* keys, unsigned count, double tps, double shift, const std::string& node,
                const char* what, std::vector<double>& times, std::vector<Value>& values,
                Convert convert) {
    std::vector<std::pair<double, Value>> kv;
    kv.reserve(count);
    for (unsigned i = 0; i < count; ++i) {
      const double t = ticksToSeconds(keys[i].mTime, tps) + shift;
      Value v = convert(keys[i].mValue);
      if (!std::isfinite(t)) {
        fail("node '" + node + "': non-finite time in " + what + " key " + std::to_string(i));
      }
      if (!finite(v)) {
        fail("node '" + node + "': non-finite " + what + " key " + std::to_string(i) +
             " (t = " + fmt(t) + " s)");
      }
      // Keys in time order (glTF 2.0 Sec. 3.11: animation inputs increase);
      // a key before its predecessor is an authoring error, not resorted.
      if (!kv.empty() && t < kv.back().first) {
        fail("node '" + node + "': " + what + " key " + std::to_string(i) + " at t = " + fmt(t) +
             " s comes before key " + std::to_string(i - 1) + " (t = " + fmt(kv.back().first) +
             " s): key times must not decrease");
      }
      kv.emplace_back(t, v);
    }
    for (auto& [t, v] : kv) {
      times.push_back(t);
      values.push_back(v);
    }
  }

  // FBX: the time assimp took off the keys of the take that animation
  // `name` comes from, to be put back (fbx_takes.hpp); 0 for other formats.
  double keyShift(const std::string& name) const {
    if (format != Format::Fbx) return 0.0;
    for (const detail::FbxTake& take : fbxTakes)
      if (take.name == name) return detail::assimpKeyShift(take);
    return fbxTakes.size() == 1 ? detail::assimpKeyShift(fbxTakes.front()) : 0.0;
  }

  void addAnimations(const aiScene* scene) {
    bool any = false;
    if (format == Format::Fbx && fbxTakes.size() > 1 &&
        std::any_of(fbxTakes.begin(), fbxTakes.end(), [](const detail::FbxTake& take) {
          return take.name.find('|') != std::string::npos;
        })) {
      // Blender's "All Actions" / "NLA Strips" export: a take per object and
      // action, each restarted at 0 from the action's first frame.
      warnings.push_back(
          "the file has " + std::to_string(fbxTakes.size()) + " takes named like Blender's " +
          "per-action export ('" + fbxTakes.front().name +
          "'): their keys start at each action's first frame, not at the scene's frames; " +
          "export with All Actions and NLA Strips off for one take of the scene");
    }
    for (unsigned a = 0; a < scene->mNumAnimations; ++a) {
      const aiAnimation* anim = scene->mAnimations[a];
      const std::string animName =
          anim->mName.length ? anim->mName.C_Str() : "#" + std::to_string(a);
      const double tps = anim->mTicksPerSecond;
      if (!(tps > 0.0) && anim->mNumChannels > 0 && format == Format::Fbx) {
        // assimp multiplies FBX key times by the frame rate, so with a rate
        // of 0 every key lands on t = 0 and the timing cannot be recovered.
        fail("animation '" + animName +
             "' has frame rate 0 (FBX TimeMode custom with CustomFrameRate 0); "
             "re-export with a real frame rate");
      }
      if (!(tps > 0.0) && anim->mNumChannels > 0) {
        warnings.push_back("animation '" + animName + "' gives no ticks per second; assuming " +
                           fmt(kFallbackTicksPerSecond));
      }
      const double shift = keyShift(animName);
      for (unsigned c = 0; c < anim->mNumChannels; ++c) {
        const aiNodeAnim* ch = anim->mChannels[c];
        const std::string name = ch->mNodeName.C_Str();
        const auto it = byName.find(name);
        if (it == byName.end()) {
          warnings.push_back("animation '" + animName + "' drives unknown node '" + name +
                             "'; channel ignored");
          continue;
        }
        Node& node = nodes[static_cast<std::size_t>(it->second)];
        if (node.animated) {
          warnings.push_back("node '" + name + "' is driven by more than one animation; '" +
                             animName + "' ignored for it");
          continue;
        }
        node.animated = true;
        NodeKeys& k = node.keys;
        readKeys(ch->mPositionKeys, ch->mNumPositionKeys, tps, shift, name, "position",
                 k.positionTimes, k.positions, toVec3);
        readKeys(ch->mRotationKeys, ch->mNumRotationKeys, tps, shift, name, "rotation",
                 k.rotationTimes, k.rotations, toQuat);
        readKeys(ch->mScalingKeys, ch->mNumScalingKeys, tps, shift, name, "scaling", k.scalingTimes,
                 k.scalings, toVec3);
        for (std::size_t i = 0; i < k.rotations.size(); ++i) {
          const double norm = k.rotations[i].norm();
          if (!(norm > 1e-12)) {
            fail("node '" + name + "': zero rotation quaternion in key " + std::to_string(i));
          }
          k.rotations[i].coeffs() /= norm;
        }
        for (const std::vector<double>* ts :
             {&k.positionTimes, &k.rotationTimes, &k.scalingTimes}) {
          if (ts->empty()) continue;
          start = any ? std::min(start, ts->front()) : ts->front();
          end = any ? std::max(end, ts->back()) : ts->back();
          any = true;
        }
      }
    }
  }

  void addCameras(const aiScene* scene) {
    for (unsigned i = 0; i < scene->mNumCameras; ++i) {
      const aiCamera* in = scene->mCameras[i];
      const auto it = byName.find(in->mName.C_Str());
      if (it == byName.end()) {
        warnings.push_back("camera '" + std::string(in->mName.C_Str()) +
                           "' is not attached to a node; ignored");
        continue;
      }
      Camera c;
      c.node = it->second;
      // assimp 5.2.5's glTF importer copies the node's translation into
      // aiCamera::mPosition although the node transform holds it too; a glTF
      // camera sits at its node's origin by definition.
      if (format != Format::Gltf) c.position = toVec3(in->mPosition);
      c.lookAt = toVec3(in->mLookAt);
      c.up = toVec3(in->mUp);
      c.hfov = in->mHorizontalFOV;
      c.aspect = in->mAspect;
      if (!finite(c.position) || !finite(c.lookAt) || !finite(c.up) || !std::isfinite(c.hfov) ||
          !std::isfinite(c.aspect)) {
        fail("camera '" + std::string(in->mName.C_Str()) + "': non-finite parameters");
      }
      cameras.push_back(c);
    }
  }
};

namespace {

std::uint32_t littleEndian32(const unsigned char* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}

// Binary glTF container (glTF 2.0 spec, "GLB File Format Specification"): a
// 12-byte header (magic "glTF", u32 version, u32 total length) and chunks
// (u32 length, u32 type, data). assimp 5.2.5 allocates a chunk's declared
// length before reading it, so a few damaged bytes cost gigabytes and
// seconds (docs/FUZZING.md); check every length against the file first.
void checkBinaryGltf(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char header[12] = {};
  if (!in.read(reinterpret_cast<char*>(header), sizeof header) ||
      std::memcmp(header, "glTF", 4) != 0) {
    return;  // not a binary glTF: nothing to check here
  }
  std::error_code ec;
  const std::uintmax_t fileSize = std::filesystem::file_size(path, ec);
  if (ec) return;
  const std::uint32_t version = littleEndian32(header + 4);
  const std::uint64_t length = littleEndian32(header + 8);
  if (length > fileSize) {
    throw InputError(path, "binary glTF header gives a length of " + std::to_string(length) +
                               " bytes, the file has " + std::to_string(fileSize));
  }
  // glTF 1.0 (KHR_binary_glTF): u32 content length, u32 content format, content.
  // glTF 2.0: chunks up to `length`.
  const std::uint64_t chunkHeader = 8;
  std::uint64_t offset = 12;
  for (int chunk = 0; offset + chunkHeader <= length; ++chunk) {
    unsigned char h[8] = {};
    in.seekg(static_cast<std::streamoff>(offset));
    if (!in.read(reinterpret_cast<char*>(h), sizeof h)) break;
    const std::uint64_t chunkLength = littleEndian32(h);
    if (chunkLength > length - offset - chunkHeader) {
      throw InputError(
          path, "binary glTF " +
                    std::string(version == 1 ? "content" : "chunk " + std::to_string(chunk)) +
                    " gives a length of " + std::to_string(chunkLength) + " bytes, only " +
                    std::to_string(length - offset - chunkHeader) + " follow");
    }
    if (version == 1) break;  // one content block, then the binary body
    offset += chunkHeader + chunkLength;
  }
}

// The one assimp import (the probe child and the real import run the same).
const aiScene* readWithAssimp(Assimp::Importer& importer, const std::string& path) {
  // Bake FBX pivots into the node transforms instead of "$AssimpFbx$" helper
  // nodes, so the node the user named is the node that moves.
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_PRESERVE_PIVOTS, false);
  // COLLADA: name nodes by their `name` attribute (what DCC outliners show),
  // not by their `id`.
  importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_USE_COLLADA_NAMES, true);
  // No PreTransformVertices / OptimizeGraph: they destroy the animated nodes.
  return importer.ReadFile(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices);
}

}  // namespace

AnimationScene::AnimationScene(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
AnimationScene::AnimationScene(AnimationScene&&) noexcept = default;
AnimationScene& AnimationScene::operator=(AnimationScene&&) noexcept = default;
AnimationScene::~AnimationScene() = default;

AnimationScene AnimationScene::load(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError(path, "no such file");
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path, "not a regular file");

  checkBinaryGltf(path);
  // A crash or hang inside assimp on this file becomes an InputError here
  // (import_probe.hpp; docs/FUZZING.md).
  // A file the importer rejects in the child (out of memory included) is not
  // imported again here.
  const std::optional<std::string> rejected = detail::probeInChild(
      path,
      [&path] {
        Assimp::Importer probe;
        if (readWithAssimp(probe, path)) return std::string();
        const std::string reason = probe.GetErrorString();
        return reason.empty() ? std::string("the importer gave no reason") : reason;
      },
      detail::importDeadline(), detail::importMemoryLimit());
  if (rejected && !rejected->empty()) throw InputError(path, "cannot import: " + *rejected);
  Assimp::Importer importer;
  const aiScene* scene = readWithAssimp(importer, path);
  if (!scene) throw InputError(path, std::string("cannot import: ") + importer.GetErrorString());
  if (!scene->mRootNode) throw InputError(path, "cannot import: the file has no node hierarchy");

  auto impl = std::make_unique<Impl>();
  impl->file = path;
  impl->format = detectFormat(scene, path);
  if (impl->format == Format::Fbx) {
    impl->fileToWorld = fbxFileToWorld(scene, path);
    impl->fbxTakes = detail::readFbxTakes(path);
  }
  impl->addNodes(scene->mRootNode, -1);
  impl->addMeshes(scene);
  impl->addAnimations(scene);
  impl->addCameras(scene);
  return AnimationScene(std::move(impl));
}

const std::string& AnimationScene::file() const { return impl_->file; }

std::vector<std::string> AnimationScene::nodeNames() const {
  std::vector<std::string> names;
  names.reserve(impl_->nodes.size());
  for (const Impl::Node& n : impl_->nodes) names.push_back(n.name);
  return names;
}

bool AnimationScene::hasNode(const std::string& name) const {
  return impl_->byName.count(name) != 0;
}

Mat4 AnimationScene::worldMatrix(const std::string& node, double t) const {
  return impl_->world(impl_->find(node), t);
}

Pose AnimationScene::worldPose(const std::string& node, double t) const {
  const Mat4 m = worldMatrix(node, t);
  Eigen::Affine3d a(m);
  Pose pose;
  pose.position = m.topRightCorner<3, 1>();
  // Polar decomposition: the rotation without the (unit) scale.
  pose.rotation = Quat(a.rotation()).normalized();
  return pose;
}

NodeKeys AnimationScene::localKeys(const std::string& node) const {
  return impl_->nodes[static_cast<std::size_t>(impl_->find(node))].keys;
}

Mat4 AnimationScene::fileToWorld() const { return impl_->fileToWorld; }

const std::vector<std::string>& AnimationScene::warnings() const { return impl_->warnings; }

double AnimationScene::startTime() const { return impl_->start; }
double AnimationScene::endTime() const { return impl_->end; }

std::optional<CameraPose> AnimationScene::camera(const std::string& node, double t) const {
  const Impl::Camera* cam = nullptr;
  if (node.empty()) {
    if (!impl_->cameras.empty()) cam = &impl_->cameras.front();
  } else {
    const int index = impl_->find(node);
    for (const Impl::Camera& c : impl_->cameras) {
      if (c.node == index) {
        cam = &c;
        break;
      }
    }
  }
  if (!cam) return std::nullopt;

  const Mat4 m = impl_->world(cam->node, t);
  const Mat3 l = m.topLeftCorner<3, 3>();
  CameraPose pose;
  pose.position = (m * cam->position.homogeneous()).head<3>();
  const Vec3 look = (l * cam->lookAt).normalized();
  Vec3 z = -look;
  Vec3 x = (l * cam->up).cross(z);
  if (x.norm() < 1e-9) x = z.unitOrthogonal();
  x.normalize();
  const Vec3 y = z.cross(x);
  Mat3 r;
  r << x, y, z;
  pose.rotation = Quat(r).normalized();
  pose.aspect = cam->aspect > 0.0 ? cam->aspect : 0.0;
  if (cam->hfov > 0.0) {
    if (impl_->format == Format::Gltf) {
      // assimp 5.2.5's glTF importer stores yfov * aspect (not a true
      // horizontal angle); undo exactly that.
      pose.yfov = pose.aspect > 0.0 ? cam->hfov / pose.aspect : cam->hfov;
    } else {
      pose.yfov =
          pose.aspect > 0.0 ? 2.0 * std::atan(std::tan(0.5 * cam->hfov) / pose.aspect) : cam->hfov;
    }
  }
  return pose;
}

std::optional<ImportedMesh> AnimationScene::mesh(const std::string& name) const {
  const int index = impl_->find(name);
  const Impl::Node& node = impl_->nodes[static_cast<std::size_t>(index)];
  if (node.meshes.empty()) return std::nullopt;
  const Mat4 m = impl_->world(index, 0.0);
  ImportedMesh out;
  for (unsigned id : node.meshes) {
    if (id >= impl_->meshes.size()) continue;
    const ImportedMesh& in = impl_->meshes[id];
    const int base = static_cast<int>(out.vertices.size());
    for (const Vec3& v : in.vertices) out.vertices.push_back((m * v.homogeneous()).head<3>());
    for (const auto& t : in.triangles)
      out.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  }
  return out;
}

}  // namespace crumple::io
