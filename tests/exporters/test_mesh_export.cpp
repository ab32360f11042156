// The mesh exports (exporters/mesh_export.hpp, gltf_export.hpp; docs/EXPORT.md)
// on a small torn sheet: every file is re-read with assimp and must hold the
// frame's vertices, faces, positions and pattern UVs exactly as given; the
// glTF keeps a tear's coincident twin vertices apart; the shot's .glb keys
// each frame node's visibility with STEP scale keys; the tear texture cuts
// exactly the masked texels; the USDA has its time samples; the bytes
// repeat.
#include <assimp/material.h>
#include <assimp/scene.h>
#include <gtest/gtest.h>

#include <assimp/Importer.hpp>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include "crumple/cache/pcache_tear.hpp"
#include "crumple/core/error.hpp"
#include "crumple/exporters/gltf_export.hpp"
#include "crumple/exporters/mesh_export.hpp"
#include "crumple/exporters/png.hpp"
#include "temp_dir.hpp"

namespace crumple::exporters {
namespace {

namespace fs = std::filesystem;

// A 10 x 5 cm sheet in 4 triangles, torn from its top edge down to the
// middle of its bottom edge: vertex 6 is vertex 4's twin (the same pattern
// point and, just cut, the same position). Regions: left 0, right 1.
cache::FrameRecord tornFrame(int number = 7) {
  cache::FrameRecord f;
  f.frame = number;
  f.time = number / 24.0;
  f.pattern = {Vec2(0, 0),       Vec2(0.05, 0),   Vec2(0.1, 0),    Vec2(0, 0.05),
               Vec2(0.05, 0.05), Vec2(0.1, 0.05), Vec2(0.05, 0.05)};
  for (const Vec2& p : f.pattern)
    f.positions.emplace_back(p.x() - 0.05, 0.2 + 0.1 * p.y(), -p.y() + 0.001 * number);
  f.triangles = {{0, 1, 4}, {0, 4, 3}, {1, 2, 5}, {1, 5, 6}};
  f.regionOfTriangle = {0, 0, 1, 1};
  f.regionTypes = {0, 0};
  return f;
}

// A TEAR block on triangle 0: 5 mm texels over [0, 5] x [0, 5] cm, paper
// only left of x = 4 cm.
cache::ExtensionBlock tearBlock() {
  mesh::TearAtlas a;
  a.texelSize = 0.005;
  a.width = 10;
  a.height = 10;
  a.mask.assign(100, 0);
  for (int j = 0; j < 10; ++j)
    for (int i = 0; i < 8; ++i) a.mask[static_cast<std::size_t>(j * 10 + i)] = 255;
  mesh::TearPatch p;
  p.triangle = 0;
  p.polygon = {Vec2(0, 0), Vec2(0.05, 0), Vec2(0.05, 0.05)};
  p.rect = {0, 0, 10, 10, Vec2(0, 0)};
  a.patches = {p};
  return cache::encodeTearAtlas(a);
}

ExportMesh meshOf(const cache::FrameRecord& f) {
  return exportMesh(f, 24.0, uvMappingOf(f.pattern, "test"));
}

std::string bytesOf(const std::string& path) {
  const auto b = test::readBytes(path);
  return std::string(b.begin(), b.end());
}

const aiScene* importFile(Assimp::Importer& importer, const std::string& path) {
  const aiScene* scene = importer.ReadFile(path, 0u);
  EXPECT_NE(scene, nullptr) << path << ": " << importer.GetErrorString();
  return scene;
}

// Every corner of every face of `m` is the mesh's: position and UV (float
// precision), face by face in order.
void expectSameCorners(const aiMesh& m, const ExportMesh& mesh, const std::string& what) {
  ASSERT_EQ(m.mNumFaces, mesh.triangles.size()) << what;
  ASSERT_TRUE(m.HasTextureCoords(0)) << what;
  for (unsigned f = 0; f < m.mNumFaces; ++f) {
    ASSERT_EQ(m.mFaces[f].mNumIndices, 3u) << what;
    for (unsigned k = 0; k < 3; ++k) {
      const unsigned i = m.mFaces[f].mIndices[k];
      const int v = mesh.triangles[f][k];
      const aiVector3D& x = m.mVertices[i];
      const aiVector3D& t = m.mTextureCoords[0][i];
      EXPECT_NEAR(x.x, mesh.positions[v].x(), 1e-7) << what << " face " << f;
      EXPECT_NEAR(x.y, mesh.positions[v].y(), 1e-7) << what << " face " << f;
      EXPECT_NEAR(x.z, mesh.positions[v].z(), 1e-7) << what << " face " << f;
      EXPECT_NEAR(t.x, mesh.uvs[v].x(), 1e-6) << what << " face " << f;
      EXPECT_NEAR(t.y, mesh.uvs[v].y(), 1e-6) << what << " face " << f;
    }
  }
}

// The JSON chunk of a .glb.
std::string glbJson(const std::string& glb) {
  if (glb.size() < 20) return {};
  std::uint32_t n = 0;
  std::memcpy(&n, glb.data() + 12, 4);
  return glb.substr(20, n);
}

int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// No PATH.<pid>.tmp is left behind.
bool noTemporaryFiles(const fs::path& dir) {
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".tmp") return false;
  return true;
}

class MeshExportTest : public test::TempDirTest {};

TEST(MeshExport, UvsAreThePatternOverItsBoundingBox) {
  const cache::FrameRecord f = tornFrame();
  const UvMapping uv = uvMappingOf(f.pattern, "test");
  EXPECT_EQ(uv.origin, Vec2(0, 0));
  EXPECT_EQ(uv.size, Vec2(0.1, 0.05));
  const ExportMesh m = meshOf(f);
  EXPECT_EQ(m.uvs[5], Vec2(1, 1));
  EXPECT_EQ(m.uvs[1], Vec2(0.5, 0));
  EXPECT_EQ(m.uvs[4], m.uvs[6]);
  EXPECT_DOUBLE_EQ(m.time, 7 / 24.0);
  EXPECT_THROW(uvMappingOf({Vec2(0, 0), Vec2(1, 0)}, "flat"), CorruptDataError);
  EXPECT_THROW(uvMappingOf({}, "empty"), CorruptDataError);
  cache::FrameRecord bad = f;
  bad.triangles[2][1] = 7;
  EXPECT_THROW(meshOf(bad), CorruptDataError);
  bad = f;
  bad.regionOfTriangle.pop_back();
  EXPECT_THROW(meshOf(bad), CorruptDataError);
  EXPECT_EQ(frameStem(7), "0007");
  EXPECT_EQ(frameStem(12345), "12345");
}

TEST_F(MeshExportTest, ObjReadsBackWithAssimpWithItsMaterialAndTexture) {
  const ExportMesh mesh = meshOf(tornFrame());
  ObjMaterial material;
  material.alphaTexture = "0007_tears.png";
  writeFileAtomically(file("0007.mtl"), mtlText(material));
  writeFileAtomically(file("0007.obj"), objText(mesh, "0007.mtl", material.name));
  EXPECT_TRUE(noTemporaryFiles(dir()));
  EXPECT_THROW(writeFileAtomically(file("missing/0007.obj"), "v 0 0 0\n"), InputError);
  const std::string text = bytesOf(file("0007.obj"));
  EXPECT_EQ(count(text, "\nv "), 7);
  EXPECT_EQ(count(text, "\nvt "), 7);
  EXPECT_EQ(count(text, "\nf "), 4);
  EXPECT_NE(text.find("\nf 2/2 6/6 7/7\n"), std::string::npos) << text;
  Assimp::Importer importer;
  const aiScene* scene = importFile(importer, file("0007.obj"));
  ASSERT_NE(scene, nullptr);
  ASSERT_EQ(scene->mNumMeshes, 1u);
  expectSameCorners(*scene->mMeshes[0], mesh, "obj");
  const aiMaterial& m = *scene->mMaterials[scene->mMeshes[0]->mMaterialIndex];
  aiString path;
  ASSERT_EQ(m.GetTexture(aiTextureType_OPACITY, 0, &path), AI_SUCCESS) << "map_d";
  EXPECT_STREQ(path.C_Str(), "0007_tears.png");
  aiColor3D kd;
  ASSERT_EQ(m.Get(AI_MATKEY_COLOR_DIFFUSE, kd), AI_SUCCESS);
  EXPECT_NEAR(kd.r, 0.92, 1e-6);
}

TEST_F(MeshExportTest, PlyIsBinaryLittleEndianWithUvsAndRegions) {
  cache::FrameRecord f = tornFrame();
  // The first data byte a line feed (0x0a, the low byte of x): assimp 5.2
  // loses it after "end_header\n", not after "end_header\r\n".
  f.positions[0].x() = static_cast<double>(std::bit_cast<float>(std::uint32_t{0xbcf2df0a}));
  const ExportMesh mesh = meshOf(f);
  writeFileAtomically(file("0007.ply"), plyBytes(mesh));
  const std::string bytes = bytesOf(file("0007.ply"));
  const std::string end = "end_header\r\n";
  const std::size_t body = bytes.find(end) + end.size();
  const std::string header = bytes.substr(0, body);
  EXPECT_EQ(header.rfind("ply\r\nformat binary_little_endian 1.0\r\n", 0), 0u);
  EXPECT_NE(header.find("element vertex 7\r\n"), std::string::npos);
  EXPECT_NE(header.find("element face 4\r\n"), std::string::npos);
  EXPECT_NE(header.find("property float u\r\nproperty float v\r\nproperty float s\r\n"
                        "property float t\r\n"),
            std::string::npos);
  EXPECT_NE(header.find("property list uchar int vertex_indices\r\nproperty int region\r\n"),
            std::string::npos);
  ASSERT_EQ(bytes.size(), body + 7 * 28 + 4 * 17);
  EXPECT_EQ(bytes[body], '\n');
  // Face 3 and its region, read by hand.
  const std::size_t face3 = body + 7 * 28 + 3 * 17;
  EXPECT_EQ(bytes[face3], 3);
  std::int32_t idx[4];
  std::memcpy(idx, bytes.data() + face3 + 1, 16);
  EXPECT_EQ(idx[0], 1);
  EXPECT_EQ(idx[2], 6);
  EXPECT_EQ(idx[3], 1) << "region";
  float uvst[4] = {};
  std::memcpy(uvst, bytes.data() + body + 5 * 28 + 12, 16);
  EXPECT_EQ(uvst[0], 1.0f);
  EXPECT_EQ(uvst[1], 1.0f);
  EXPECT_EQ(uvst[2], 1.0f);
  EXPECT_EQ(uvst[3], 1.0f);
  Assimp::Importer importer;
  const aiScene* scene = importFile(importer, file("0007.ply"));
  ASSERT_NE(scene, nullptr);
  ASSERT_EQ(scene->mNumMeshes, 1u);
  expectSameCorners(*scene->mMeshes[0], mesh, "ply");
}

TEST_F(MeshExportTest, GlbKeepsTheCachesVerticesEvenCoincidentTwins) {
  const ExportMesh mesh = meshOf(tornFrame());
  ASSERT_EQ(mesh.positions[4], mesh.positions[6]);
  ASSERT_EQ(mesh.uvs[4], mesh.uvs[6]);
  writeGlb(file("0007.glb"), mesh, Vec3(0.5, 0.25, 0.125));
  EXPECT_TRUE(noTemporaryFiles(dir()));
  Assimp::Importer importer;
  const aiScene* scene = importFile(importer, file("0007.glb"));
  ASSERT_NE(scene, nullptr);
  ASSERT_EQ(scene->mNumMeshes, 1u);
  const aiMesh& m = *scene->mMeshes[0];
  EXPECT_EQ(m.mNumVertices, 7u) << "assimp's exporter would join vertex 6 into vertex 4";
  expectSameCorners(m, mesh, "glb");
  for (unsigned f = 0; f < m.mNumFaces; ++f)
    for (unsigned k = 0; k < 3; ++k)
      EXPECT_EQ(m.mFaces[f].mIndices[k], static_cast<unsigned>(mesh.triangles[f][k]));
  const aiMaterial& mat = *scene->mMaterials[m.mMaterialIndex];
  aiColor4D base;
  ASSERT_EQ(mat.Get(AI_MATKEY_BASE_COLOR, base), AI_SUCCESS);
  EXPECT_FLOAT_EQ(base.g, 0.25f);
  const std::string json = glbJson(bytesOf(file("0007.glb")));
  EXPECT_NE(json.find("\"TEXCOORD_0\""), std::string::npos);
  EXPECT_NE(json.find("\"doubleSided\":true"), std::string::npos);
  EXPECT_EQ(json.find("animations"), std::string::npos);
}

TEST_F(MeshExportTest, ShotGlbKeysEachFramesVisibilityWithStepScaleKeys) {
  GlbShot shot(24.0, Vec3(1, 1, 1));
  std::vector<ExportMesh> meshes;
  for (const int f : {10, 11, 12}) {
    cache::FrameRecord r = tornFrame(f);
    if (f == 12) {  // another topology: the right half gone
      r.triangles.resize(2);
      r.regionOfTriangle.resize(2);
    }
    meshes.push_back(meshOf(r));
    shot.add(meshes.back());
  }
  EXPECT_THROW(shot.add(meshes.front()), std::invalid_argument);
  shot.write(file("shot.glb"));
  const std::string json = glbJson(bytesOf(file("shot.glb")));
  EXPECT_EQ(count(json, "\"interpolation\":\"STEP\""), 3);
  EXPECT_EQ(count(json, "LINEAR"), 0);
  EXPECT_EQ(count(json, "\"path\":\"scale\""), 3);

  Assimp::Importer importer;
  const aiScene* scene = importFile(importer, file("shot.glb"));
  ASSERT_NE(scene, nullptr);
  const aiNode* root = scene->mRootNode;
  ASSERT_EQ(root->mNumChildren, 3u);
  ASSERT_EQ(scene->mNumAnimations, 1u);
  const aiAnimation& anim = *scene->mAnimations[0];
  const double tps = anim.mTicksPerSecond > 0.0 ? anim.mTicksPerSecond : 1.0;
  std::map<std::string, const aiNodeAnim*> channels;
  for (unsigned c = 0; c < anim.mNumChannels; ++c)
    channels[anim.mChannels[c]->mNodeName.C_Str()] = anim.mChannels[c];
  ASSERT_EQ(channels.size(), 3u);
  for (unsigned i = 0; i < 3; ++i) {
    const aiNode* node = root->mChildren[i];
    const int frame = 10 + static_cast<int>(i);
    EXPECT_EQ(std::string(node->mName.C_Str()), "frame_00" + std::to_string(frame));
    ASSERT_EQ(node->mNumMeshes, 1u);
    const aiMesh& m = *scene->mMeshes[node->mMeshes[0]];
    EXPECT_EQ(m.mNumVertices, 7u);
    expectSameCorners(m, meshes[i], node->mName.C_Str());
    ASSERT_EQ(channels.count(node->mName.C_Str()), 1u);
    const aiNodeAnim& ch = *channels[node->mName.C_Str()];
    // Keys: 0 from frame 10 (but for the first node), 1 at its frame, 0 from the next.
    std::vector<std::pair<double, float>> keys;
    for (unsigned k = 0; k < ch.mNumScalingKeys; ++k)
      keys.emplace_back(ch.mScalingKeys[k].mTime / tps, ch.mScalingKeys[k].mValue.x);
    std::vector<std::pair<double, float>> expected;
    if (i > 0) expected.emplace_back(10 / 24.0, 0.0f);
    expected.emplace_back(frame / 24.0, 1.0f);
    if (i < 2) expected.emplace_back((frame + 1) / 24.0, 0.0f);
    ASSERT_EQ(keys.size(), expected.size()) << node->mName.C_Str();
    for (std::size_t k = 0; k < keys.size(); ++k) {
      EXPECT_NEAR(keys[k].first, expected[k].first, 1e-6);
      EXPECT_EQ(keys[k].second, expected[k].second);
    }
  }
}

TEST_F(MeshExportTest, TearTextureCutsExactlyTheMaskedTexelsOfThePatchTriangle) {
  cache::FrameRecord f = tornFrame();
  const UvMapping uv = uvMappingOf(f.pattern, "test");
  EXPECT_FALSE(tearTexture(f, uv).has_value()) << "no TEAR block, no texture";
  f.extensions.push_back(tearBlock());
  const auto tex = tearTexture(f, uv);
  ASSERT_TRUE(tex.has_value());
  ASSERT_EQ(tex->width, 20);  // 10 cm / 5 mm
  ASSERT_EQ(tex->height, 10);
  int zeros = 0;
  for (int r = 0; r < tex->height; ++r) {
    for (int i = 0; i < tex->width; ++i) {
      const std::uint8_t* px = tex->at(i, r);
      EXPECT_TRUE(px[0] == px[3] && px[1] == px[3] && px[2] == px[3]);
      // The texel's centre in the pattern (row 0 at the top, v = 1).
      const double x = (i + 0.5) * 0.005, y = (tex->height - r - 0.5) * 0.005;
      if (std::abs(y - x) < 1e-9) continue;  // on triangle 0's diagonal
      const bool inPatch = y < x && x < 0.05;
      const bool cut = inPatch && x > 0.04;
      EXPECT_EQ(px[3], cut ? 0 : 255) << "texel " << i << ", " << r;
      zeros += px[3] == 0 ? 1 : 0;
    }
  }
  EXPECT_GE(zeros, 17);
  writePng(file("tears.png"), *tex);
  const ImageRGBA8 back = readPng(file("tears.png"));
  EXPECT_EQ(back.pixels, tex->pixels);
  // Capped: no side above maxSide, the same square.
  const auto small = tearTexture(f, uv, 8);
  ASSERT_TRUE(small.has_value());
  EXPECT_EQ(small->width, 8);
  EXPECT_EQ(small->height, 4);
  // A patch on a triangle the frame does not have.
  f.triangles.resize(0);
  f.regionOfTriangle.resize(0);
  EXPECT_THROW(tearTexture(f, uv), CorruptDataError);
}

TEST_F(MeshExportTest, UsdaKeysPointsEveryFrameAndTopologyWhereItChanges) {
  const auto write = [&](const std::string& name) {
    UsdaWriter usda(file(name), "a \"torn\" sheet", 24.0);
    for (const int f : {3, 4, 5, 6}) {
      cache::FrameRecord r = tornFrame(f);
      if (f >= 5) {
        r.triangles.resize(2);
        r.regionOfTriangle.resize(2);
      }
      usda.add(meshOf(r));
    }
    EXPECT_THROW(usda.add(meshOf(tornFrame(2))), std::invalid_argument);
    EXPECT_FALSE(fs::exists(file(name))) << "nothing before close()";
    usda.close();
    EXPECT_EQ(usda.framesAdded(), 4);
    EXPECT_EQ(usda.topologySamples(), 2);
  };
  write("shot.usda");
  const std::string text = bytesOf(file("shot.usda"));
  EXPECT_EQ(text.rfind("#usda 1.0\n", 0), 0u);
  for (const char* meta :
       {"startTimeCode = 3\n", "endTimeCode = 6\n", "timeCodesPerSecond = 24\n", "upAxis = \"Y\"\n",
        "metersPerUnit = 1\n", "doc = \"crumple export of scene 'a \\\"torn\\\""})
    EXPECT_NE(text.find(meta), std::string::npos) << meta;
  // Each timeSamples block: its sample lines "N: [...]," up to the closing brace.
  std::map<std::string, std::vector<int>> samples;
  const std::regex block(R"((\S+)\.timeSamples = \{\n((?:\s+-?\d+: \[.*\],\n)*)\s+\})");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), block);
       it != std::sregex_iterator(); ++it) {
    const std::string body = (*it)[2];
    const std::regex sample(R"(\s+(-?\d+): \[)");
    for (auto s = std::sregex_iterator(body.begin(), body.end(), sample);
         s != std::sregex_iterator(); ++s)
      samples[(*it)[1]].push_back(std::stoi((*s)[1]));
  }
  EXPECT_EQ(samples["points"], (std::vector<int>{3, 4, 5, 6}));
  EXPECT_EQ(samples["extent"], (std::vector<int>{3, 4, 5, 6}));
  for (const char* attr :
       {"faceVertexCounts", "faceVertexIndices", "primvars:st", "primvars:region"})
    EXPECT_EQ(samples[attr], (std::vector<int>{3, 5})) << attr;
  EXPECT_NE(text.find("            5: [3, 3],\n"), std::string::npos);
  EXPECT_NE(text.find("            3: [0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 6],\n"), std::string::npos);
  EXPECT_NE(text.find("interpolation = \"vertex\""), std::string::npos);
  EXPECT_NE(text.find("uniform token subdivisionScheme = \"none\""), std::string::npos);
  // Balanced braces and brackets: it parses at least structurally.
  EXPECT_EQ(count(text, "{"), count(text, "}"));
  EXPECT_EQ(count(text, "["), count(text, "]"));
  EXPECT_EQ(count(text, "("), count(text, ")"));
  write("again.usda");
  EXPECT_EQ(bytesOf(file("again.usda")), text);
}

TEST_F(MeshExportTest, IdenticalInputGivesIdenticalBytes) {
  cache::FrameRecord f = tornFrame();
  f.extensions.push_back(tearBlock());
  const ExportMesh mesh = meshOf(f);
  for (const char* run : {"a", "b"}) {
    const std::string dir = file(run);
    fs::create_directories(dir);
    writeFileAtomically(dir + "/f.obj", objText(mesh, "f.mtl", "paper"));
    writeFileAtomically(dir + "/f.ply", plyBytes(mesh));
    writeGlb(dir + "/f.glb", mesh, Vec3(1, 1, 1));
    GlbShot shot(24.0, Vec3(1, 1, 1));
    shot.add(mesh);
    shot.write(dir + "/shot.glb");
    writePng(dir + "/t.png", *tearTexture(f, uvMappingOf(f.pattern, "t")));
  }
  for (const char* name : {"f.obj", "f.ply", "f.glb", "shot.glb", "t.png"})
    EXPECT_EQ(bytesOf(file(std::string("a/") + name)), bytesOf(file(std::string("b/") + name)))
        << name;
}

}  // namespace
}  // namespace crumple::exporters
