// glTF 2.0 through assimp's "glb2" exporter (docs/EXPORT.md "glTF").
//
// Two things assimp 5.2 does not do the way an export of a cache needs:
// - The glb2 exporter always runs JoinIdenticalVertices first, unless the
//   scene says that step already ran. A tear's twin vertices share their
//   UVs, and at the frame the cut is made their positions too, so they
//   would be welded and the mesh would no longer be the cache's. The scene
//   handed to the exporter is therefore one an assimp Importer made and
//   marked as joined (a one-triangle OBJ read with that step), emptied and
//   filled with the frame's mesh: public API only, and the vertex counts
//   stay the cache's (tests/exporters/test_mesh_export.cpp checks it).
// - Its animation samplers are always LINEAR (aiVectorKey has no
//   interpolation in 5.2). The visibility keys must hold their value, so
//   the JSON chunk of the shot's .glb is patched: every
//   "interpolation":"LINEAR" becomes "interpolation":"STEP" followed by two
//   spaces, the same length, so no offset in the file moves.
#include "crumple/exporters/gltf_export.hpp"

#include <assimp/SceneCombiner.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "crumple/core/error.hpp"

namespace crumple::exporters {
namespace {

// The steps the glb2 exporter would run (its mEnforcePP in assimp 5.2).
constexpr unsigned kExporterSteps =
    aiProcess_JoinIdenticalVertices | aiProcess_Triangulate | aiProcess_SortByPType;

// An empty scene that assimp takes as already joined, triangulated and
// sorted (see the top of this file).
std::unique_ptr<aiScene> emptyPreparedScene() {
  static constexpr char kTriangle[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  Assimp::Importer importer;
  if (importer.ReadFileFromMemory(kTriangle, sizeof kTriangle - 1, kExporterSteps, "obj") ==
      nullptr)
    throw std::runtime_error(std::string("assimp cannot make an empty scene: ") +
                             importer.GetErrorString());
  std::unique_ptr<aiScene> scene(importer.GetOrphanedScene());
  delete scene->mRootNode;
  scene->mRootNode = nullptr;
  for (unsigned i = 0; i < scene->mNumMeshes; ++i) delete scene->mMeshes[i];
  delete[] scene->mMeshes;
  scene->mMeshes = nullptr;
  scene->mNumMeshes = 0;
  for (unsigned i = 0; i < scene->mNumMaterials; ++i) delete scene->mMaterials[i];
  delete[] scene->mMaterials;
  scene->mMaterials = nullptr;
  scene->mNumMaterials = 0;
  for (unsigned i = 0; i < scene->mNumAnimations; ++i) delete scene->mAnimations[i];
  delete[] scene->mAnimations;
  scene->mAnimations = nullptr;
  scene->mNumAnimations = 0;
  scene->mFlags = 0;
  return scene;
}

// The paper: double-sided, not metallic, fully rough, of the given colour.
aiMaterial* paperMaterial(const Vec3& diffuse) {
  auto* m = new aiMaterial();
  const aiString name("paper_material");
  m->AddProperty(&name, AI_MATKEY_NAME);
  const aiColor4D colour(static_cast<ai_real>(diffuse.x()), static_cast<ai_real>(diffuse.y()),
                         static_cast<ai_real>(diffuse.z()), 1.0f);
  m->AddProperty(&colour, 1, AI_MATKEY_COLOR_DIFFUSE);
  m->AddProperty(&colour, 1, AI_MATKEY_BASE_COLOR);
  const bool twoSided = true;  // a bool property, as the glTF exporter reads it
  m->AddProperty(&twoSided, 1, AI_MATKEY_TWOSIDED);
  const float metallic = 0.0f, roughness = 1.0f;
  m->AddProperty(&metallic, 1, AI_MATKEY_METALLIC_FACTOR);
  m->AddProperty(&roughness, 1, AI_MATKEY_ROUGHNESS_FACTOR);
  return m;
}

// A frame's mesh as an aiMesh: one vertex per cache vertex, UV channel 0.
aiMesh* toAiMesh(const ExportMesh& mesh, const std::string& name) {
  auto* m = new aiMesh();
  m->mName = aiString(name);
  m->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  m->mMaterialIndex = 0;
  const auto n = static_cast<unsigned>(mesh.positions.size());
  m->mNumVertices = n;
  m->mVertices = new aiVector3D[n];
  m->mTextureCoords[0] = new aiVector3D[n];
  m->mNumUVComponents[0] = 2;
  for (unsigned i = 0; i < n; ++i) {
    const Vec3& x = mesh.positions[i];
    m->mVertices[i] = aiVector3D(static_cast<ai_real>(x.x()), static_cast<ai_real>(x.y()),
                                 static_cast<ai_real>(x.z()));
    m->mTextureCoords[0][i] = aiVector3D(static_cast<ai_real>(mesh.uvs[i].x()),
                                         static_cast<ai_real>(mesh.uvs[i].y()), 0.0f);
  }
  const auto t = static_cast<unsigned>(mesh.triangles.size());
  m->mNumFaces = t;
  m->mFaces = new aiFace[t];
  for (unsigned f = 0; f < t; ++f) {
    aiFace& face = m->mFaces[f];
    face.mNumIndices = 3;
    face.mIndices = new unsigned[3];
    for (unsigned k = 0; k < 3; ++k) face.mIndices[k] = static_cast<unsigned>(mesh.triangles[f][k]);
  }
  return m;
}

// Exports through assimp into memory.
std::string exportGlb(const aiScene& scene, const std::string& path) {
  Assimp::Exporter exporter;
  const aiExportDataBlob* blob = exporter.ExportToBlob(&scene, "glb2", 0u);
  if (blob == nullptr)
    throw InputError(path,
                     std::string("assimp's glTF exporter failed: ") + exporter.GetErrorString());
  return std::string(static_cast<const char*>(blob->data), blob->size);
}

std::uint32_t readU32(const std::string& b, std::size_t at) {
  std::uint32_t v = 0;
  for (int k = 3; k >= 0; --k) v = (v << 8) | static_cast<unsigned char>(b[at + k]);
  return v;
}

// Turns every LINEAR sampler of the .glb's JSON chunk into STEP (same length).
int makeSamplersStep(std::string& glb) {
  if (glb.size() < 20 || glb.compare(0, 4, "glTF") != 0 || readU32(glb, 16) != 0x4E4F534Au)
    throw std::logic_error("assimp's glb2 exporter wrote no JSON chunk first");
  const std::size_t begin = 20, end = begin + readU32(glb, 12);
  if (end > glb.size()) throw std::logic_error("assimp's glb2 exporter wrote a truncated chunk");
  static constexpr std::string_view kLinear = "\"interpolation\":\"LINEAR\"";
  static constexpr std::string_view kStep = "\"interpolation\":\"STEP\"  ";
  static_assert(kLinear.size() == kStep.size());
  int replaced = 0;
  for (std::size_t at = glb.find(kLinear, begin); at != std::string::npos && at < end;
       at = glb.find(kLinear, at + kStep.size())) {
    glb.replace(at, kStep.size(), kStep);
    ++replaced;
  }
  return replaced;
}

// Node, mesh and material names differ: assimp's glTF writer makes every id
// unique across them, and finds an animation's node by its id.
std::string nodeName(int frame) { return "frame_" + frameStem(frame); }

}  // namespace

void writeGlb(const std::string& path, const ExportMesh& mesh, const Vec3& diffuse) {
  std::unique_ptr<aiScene> scene = emptyPreparedScene();
  scene->mNumMaterials = 1;
  scene->mMaterials = new aiMaterial* [1] { paperMaterial(diffuse) };
  scene->mNumMeshes = 1;
  scene->mMeshes = new aiMesh* [1] { toAiMesh(mesh, "paper_mesh") };
  scene->mRootNode = new aiNode("paper");
  scene->mRootNode->mNumMeshes = 1;
  scene->mRootNode->mMeshes = new unsigned[1]{0};
  writeFileAtomically(path, exportGlb(*scene, path));
}

struct GlbShot::Impl {
  double fps = 24.0;
  Vec3 diffuse = Vec3::Ones();
  std::vector<int> frames;
  std::vector<std::unique_ptr<aiMesh>> meshes;
};

GlbShot::GlbShot(double fps, const Vec3& diffuse) : impl_(std::make_unique<Impl>()) {
  if (!(fps > 0.0) || !std::isfinite(fps))
    throw std::invalid_argument("GlbShot: fps must be finite and > 0");
  impl_->fps = fps;
  impl_->diffuse = diffuse;
}

GlbShot::~GlbShot() = default;

int GlbShot::frames() const { return static_cast<int>(impl_->frames.size()); }

void GlbShot::add(const ExportMesh& mesh) {
  if (!impl_->frames.empty() && mesh.frame <= impl_->frames.back())
    throw std::invalid_argument("GlbShot::add: frame " + std::to_string(mesh.frame) +
                                " after frame " + std::to_string(impl_->frames.back()));
  impl_->meshes.emplace_back(toAiMesh(mesh, "mesh_" + frameStem(mesh.frame)));
  impl_->frames.push_back(mesh.frame);
}

void GlbShot::write(const std::string& path) const {
  const Impl& s = *impl_;
  if (s.frames.empty()) throw std::logic_error("GlbShot::write without frames");
  const auto n = static_cast<unsigned>(s.frames.size());
  std::unique_ptr<aiScene> scene = emptyPreparedScene();
  scene->mNumMaterials = 1;
  scene->mMaterials = new aiMaterial* [1] { paperMaterial(s.diffuse) };
  // The scene owns what it holds: copies of the meshes (assimp's own copy).
  scene->mNumMeshes = n;
  scene->mMeshes = new aiMesh*[n]();
  for (unsigned i = 0; i < n; ++i) {
    aiMesh* copy = nullptr;
    Assimp::SceneCombiner::Copy(&copy, s.meshes[i].get());
    scene->mMeshes[i] = copy;
  }
  scene->mRootNode = new aiNode("shot");
  scene->mRootNode->mNumChildren = n;
  scene->mRootNode->mChildren = new aiNode*[n]();
  for (unsigned i = 0; i < n; ++i) {
    auto* node = new aiNode(nodeName(s.frames[i]));
    node->mParent = scene->mRootNode;
    node->mNumMeshes = 1;
    node->mMeshes = new unsigned[1]{i};
    scene->mRootNode->mChildren[i] = node;
  }
  // Visibility: scale 1 at the node's frame, 0 before and after, held (STEP).
  auto* anim = new aiAnimation();
  scene->mNumAnimations = 1;
  scene->mAnimations = new aiAnimation* [1] { anim };
  anim->mName = aiString("visibility");
  anim->mTicksPerSecond = s.fps;  // a tick is a frame
  anim->mDuration = static_cast<double>(s.frames.back() - s.frames.front());
  anim->mNumChannels = n;
  anim->mChannels = new aiNodeAnim*[n]();
  for (unsigned i = 0; i < n; ++i) {
    auto* channel = new aiNodeAnim();
    anim->mChannels[i] = channel;
    channel->mNodeName = aiString(nodeName(s.frames[i]));
    std::vector<aiVectorKey> keys;
    const aiVector3D hidden(0.0f, 0.0f, 0.0f), shown(1.0f, 1.0f, 1.0f);
    if (i > 0) keys.emplace_back(static_cast<double>(s.frames.front()), hidden);
    keys.emplace_back(static_cast<double>(s.frames[i]), shown);
    if (i + 1 < n) keys.emplace_back(static_cast<double>(s.frames[i + 1]), hidden);
    channel->mNumScalingKeys = static_cast<unsigned>(keys.size());
    channel->mScalingKeys = new aiVectorKey[keys.size()];
    std::copy(keys.begin(), keys.end(), channel->mScalingKeys);
  }
  std::string glb = exportGlb(*scene, path);
  const int replaced = makeSamplersStep(glb);
  if (replaced != static_cast<int>(n))
    throw std::logic_error("assimp's glb2 exporter wrote " + std::to_string(replaced) +
                           " LINEAR samplers for " + std::to_string(n) + " channels");
  writeFileAtomically(path, glb);
}

}  // namespace crumple::exporters
