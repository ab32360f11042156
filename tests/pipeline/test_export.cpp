// `crumple export` on real shots (docs/EXPORT.md): the crumple
// sample (its topology changes as it crumples) exported in every format
// through the CLI and re-read with assimp, frame by frame against the cache
// (vertex and face counts, every corner's position, bounds, UVs in [0, 1]);
// the shot's .glb nodes and visibility channels; the USDA's time samples;
// byte-identical repeats and farm chunks; bad formats and ranges; and a torn
// sheet (tear-straight) whose OBJ frames carry their tear texture.
#include <assimp/material.h>
#include <assimp/scene.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cstdlib>
#include <limits>
#include <map>
#include <regex>
#include <set>

#include "crumple/cache/pcache.hpp"
#include "crumple/cache/pcache_tear.hpp"
#include "crumple/exporters/png.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/pipeline/export.hpp"
#include "crumple/pipeline/output_lock.hpp"
#include "crumple/pipeline/refine.hpp"
#include "crumple/pipeline/shot.hpp"
#include "sample_shot.hpp"
#include "test_util.hpp"

using namespace crumple;
using namespace crumple::testing;  // the shared helpers (test_util.hpp)
namespace fs = std::filesystem;

namespace {

std::string stem(int frame) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%04d", frame);
  return buf;
}

struct Box {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = -Vec3::Constant(std::numeric_limits<double>::infinity());
  void add(const Vec3& x) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
};

// The bounds of the frame's vertices that some triangle uses (OBJ and PLY
// importers keep only those), or of all of them.
Box cacheBounds(const cache::FrameRecord& f, bool usedOnly) {
  Box b;
  if (!usedOnly) {
    for (const Vec3& x : f.positions) b.add(x);
    return b;
  }
  for (const auto& t : f.triangles)
    for (const int v : t) b.add(f.positions[static_cast<std::size_t>(v)]);
  return b;
}

Box meshBounds(const aiMesh& m) {
  Box b;
  for (unsigned i = 0; i < m.mNumVertices; ++i)
    b.add(Vec3(m.mVertices[i].x, m.mVertices[i].y, m.mVertices[i].z));
  return b;
}

void expectBounds(const Box& got, const Box& want, const std::string& what) {
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(got.lo[k], want.lo[k], 1e-7) << what;
    EXPECT_NEAR(got.hi[k], want.hi[k], 1e-7) << what;
  }
}

// Faces, corners (positions of the cache's vertices, in order) and UVs in [0, 1].
void expectFrame(const aiMesh& m, const cache::FrameRecord& f, const std::string& what) {
  ASSERT_EQ(m.mNumFaces, f.triangles.size()) << what;
  ASSERT_TRUE(m.HasTextureCoords(0)) << what;
  for (unsigned t = 0; t < m.mNumFaces; ++t) {
    ASSERT_EQ(m.mFaces[t].mNumIndices, 3u) << what;
    for (unsigned k = 0; k < 3; ++k) {
      const aiVector3D& x = m.mVertices[m.mFaces[t].mIndices[k]];
      const Vec3& want = f.positions[static_cast<std::size_t>(f.triangles[t][k])];
      ASSERT_LT((Vec3(x.x, x.y, x.z) - want).norm(), 1e-7) << what << " face " << t;
    }
  }
  for (unsigned i = 0; i < m.mNumVertices; ++i) {
    const aiVector3D& uv = m.mTextureCoords[0][i];
    ASSERT_TRUE(uv.x >= 0.0f && uv.x <= 1.0f && uv.y >= 0.0f && uv.y <= 1.0f)
        << what << " uv " << uv.x << ", " << uv.y;
  }
}

int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// The frames of each timeSamples block of a USDA layer.
std::map<std::string, std::vector<int>> usdaSamples(const std::string& text) {
  std::map<std::string, std::vector<int>> samples;
  std::string attr;
  std::size_t pos = 0;
  while (pos < text.size()) {
    const std::size_t eol = text.find('\n', pos);
    const std::string line = text.substr(pos, eol - pos);
    pos = eol == std::string::npos ? text.size() : eol + 1;
    static const std::regex open(R"(^\s+\S+ (\S+)\.timeSamples = \{$)");
    // A sample "  F: [...]," read by hand: std::regex recurses once per
    // character and overflows the stack on a long array.
    const std::size_t first = line.find_first_not_of(' ');
    const std::size_t colon = line.find(": [");
    const bool isSample = first != std::string::npos && colon != std::string::npos &&
                          colon > first && line.find_first_not_of("-0123456789", first) == colon &&
                          line.ends_with("],");
    std::smatch m;
    if (line.size() < 200 && std::regex_match(line, m, open)) {
      attr = m[1];
      samples[attr];
    } else if (!attr.empty() && isSample) {
      samples[attr].push_back(std::stoi(line.substr(first, colon - first)));
    } else if (line.find('}') != std::string::npos) {
      attr.clear();
    }
  }
  return samples;
}

// Every regular file below `dir` but the folder's lock file (it stays,
// holding no lock, after the export), relative path -> bytes.
std::map<std::string, std::string> filesIn(const fs::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file() && e.path().filename() != pipeline::kOutputLockFile)
      out[fs::relative(e.path(), dir).string()] = readFile(e.path());
  return out;
}

const char* kFormats[] = {"obj", "ply", "gltf", "usda"};

TEST(Export, EveryFormatOfTheCrumpleShotReadsBackWithAssimpAsTheCache) {
  TempDir tmp;
  const std::string cachePath = simulateSample("crumple", tmp);
  const fs::path shotDir = fs::path(cachePath).parent_path();
  for (const char* format : kFormats) {
    const auto r = runCrumple("export " + cachePath + " --format " + format);
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("PROGRESS 100"), std::string::npos) << r.output;
    EXPECT_TRUE(fs::is_directory(shotDir / "export" / format)) << "the default folder";
  }
  const cache::CacheReader reader(cachePath);
  ASSERT_GT(reader.frameCount(), 100u);
  std::vector<int> frames, topologyChanges;
  std::set<std::size_t> triangleCounts;
  cache::FrameRecord previous;
  Assimp::Importer shotImporter;
  const aiScene* shot = shotImporter.ReadFile((shotDir / "export/gltf/shot.glb").string(), 0u);
  ASSERT_NE(shot, nullptr) << shotImporter.GetErrorString();
  ASSERT_EQ(shot->mRootNode->mNumChildren, reader.frameCount());
  ASSERT_EQ(shot->mNumAnimations, 1u);
  ASSERT_EQ(shot->mAnimations[0]->mNumChannels, reader.frameCount());
  std::map<std::string, const aiNodeAnim*> channels;
  for (unsigned c = 0; c < shot->mAnimations[0]->mNumChannels; ++c)
    channels[shot->mAnimations[0]->mChannels[c]->mNodeName.C_Str()] =
        shot->mAnimations[0]->mChannels[c];
  const double tps =
      shot->mAnimations[0]->mTicksPerSecond > 0.0 ? shot->mAnimations[0]->mTicksPerSecond : 1.0;
  for (std::size_t i = 0; i < reader.frameCount(); ++i) {
    // The export's default: the crumpling model's curved regions refined.
    cache::FrameRecord f = reader.readFrame(i);
    pipeline::refineFrame(f, mesh::RefineOptions{});
    const std::string s = stem(f.frame);
    frames.push_back(f.frame);
    triangleCounts.insert(f.triangles.size());
    if (i == 0 || f.triangles != previous.triangles || f.pattern != previous.pattern ||
        f.regionOfTriangle != previous.regionOfTriangle)
      topologyChanges.push_back(f.frame);
    previous = f;
    // OBJ: one v and vt per cache vertex.
    const std::string obj = readFile(shotDir / "export/obj" / (s + ".obj"));
    EXPECT_EQ(count(obj, "\nv "), static_cast<int>(f.positions.size())) << s;
    EXPECT_EQ(count(obj, "\nvt "), static_cast<int>(f.positions.size())) << s;
    EXPECT_NE(obj.find("mtllib paper.mtl\n"), std::string::npos) << "no tears in this shot";
    for (const char* ext : {".obj", ".ply", ".glb"}) {
      const std::string dir = std::string(ext) == ".glb" ? "gltf" : std::string(ext + 1);
      const std::string path = (shotDir / "export" / dir / (s + ext)).string();
      Assimp::Importer importer;
      const aiScene* scene = importer.ReadFile(path, 0u);
      ASSERT_NE(scene, nullptr) << path << ": " << importer.GetErrorString();
      ASSERT_EQ(scene->mNumMeshes, 1u) << path;
      const aiMesh& m = *scene->mMeshes[0];
      expectFrame(m, f, path);
      if (std::string(ext) == ".glb") {
        EXPECT_EQ(m.mNumVertices, f.positions.size()) << path;
        expectBounds(meshBounds(m), cacheBounds(f, false), path);
      } else {
        expectBounds(meshBounds(m), cacheBounds(f, true), path);
      }
    }
    // The shot's node of this frame: its mesh and its visibility keys.
    const aiNode* node = shot->mRootNode->mChildren[i];
    ASSERT_EQ(std::string(node->mName.C_Str()), "frame_" + s);
    ASSERT_EQ(node->mNumMeshes, 1u);
    const aiMesh& m = *shot->mMeshes[node->mMeshes[0]];
    EXPECT_EQ(m.mNumVertices, f.positions.size());
    expectFrame(m, f, "shot.glb " + s);
    ASSERT_EQ(channels.count(node->mName.C_Str()), 1u) << s;
    const aiNodeAnim& ch = *channels[node->mName.C_Str()];
    const std::size_t keys = 1 + (i > 0 ? 1 : 0) + (i + 1 < reader.frameCount() ? 1 : 0);
    ASSERT_EQ(ch.mNumScalingKeys, keys) << s;
    const aiVectorKey& shown = ch.mScalingKeys[i > 0 ? 1 : 0];
    EXPECT_NEAR(shown.mTime / tps, f.frame / reader.header().fps, 1e-6) << s;
    EXPECT_EQ(shown.mValue, aiVector3D(1, 1, 1)) << s;
    for (unsigned k = 0; k < ch.mNumScalingKeys; ++k) {
      if (&ch.mScalingKeys[k] != &shown) {
        EXPECT_EQ(ch.mScalingKeys[k].mValue, aiVector3D(0, 0, 0));
      }
    }
  }
  EXPECT_GT(triangleCounts.size(), 3u) << "the crumple shot changes its topology";
  // USDA: points and extent every frame, the topology where it changed.
  const std::string usda = readFile(shotDir / "export/usda/shot.usda");
  const auto samples = usdaSamples(usda);
  ASSERT_EQ(samples.size(), 6u) << usda.substr(0, 2000);
  EXPECT_EQ(samples.at("points"), frames);
  EXPECT_EQ(samples.at("extent"), frames);
  for (const char* attr :
       {"faceVertexCounts", "faceVertexIndices", "primvars:st", "primvars:region"})
    EXPECT_EQ(samples.at(attr), topologyChanges) << attr;
  EXPECT_NE(usda.find("startTimeCode = " + std::to_string(frames.front()) + "\n"),
            std::string::npos);
  EXPECT_NE(usda.find("endTimeCode = " + std::to_string(frames.back()) + "\n"), std::string::npos);
  EXPECT_NE(usda.find("timeCodesPerSecond = 24\n"), std::string::npos);
  EXPECT_EQ(count(usda, "{"), count(usda, "}"));
  EXPECT_EQ(count(usda, "["), count(usda, "]"));
  // No temporary file is left.
  for (const auto& e : fs::recursive_directory_iterator(shotDir / "export"))
    EXPECT_EQ(e.path().string().find(".tmp"), std::string::npos) << e.path();
}

TEST(Export, RepeatsByteForByteAndFarmChunksGiveTheSameFiles) {
  TempDir tmp;
  const std::string cachePath = simulateSample("crumple", tmp);
  for (const char* format : kFormats) {
    pipeline::ExportOptions options;
    options.format = pipeline::parseExportFormat(format);
    options.log = nullptr;
    for (const char* run : {"a", "b"}) {
      options.outDir = (tmp / run / format).string();
      const auto report = pipeline::exportCache(cachePath, options);
      EXPECT_EQ(report.frames, 109);
    }
    const auto a = filesIn(tmp / "a" / format), b = filesIn(tmp / "b" / format);
    const std::size_t files = std::string(format) == "usda"  ? 1u
                              : std::string(format) == "ply" ? 109u
                                                             : 110u;  // + paper.mtl, shot.glb
    EXPECT_EQ(a.size(), files) << format;
    EXPECT_TRUE(a == b) << format << ": a second export differs";
    // A farm chunk writes the very same frame files.
    const auto r = runCrumple("export " + cachePath + " --format " + format + " --frames 40-50" +
                              " --out " + (tmp / "chunk" / format).string());
    ASSERT_EQ(r.status, 0) << r.output;
    const auto chunk = filesIn(tmp / "chunk" / format);
    for (const auto& [name, bytes] : chunk) {
      if (name.rfind("shot", 0) == 0) continue;
      ASSERT_EQ(a.count(name), 1u) << name;
      EXPECT_TRUE(a.at(name) == bytes) << format << " " << name;
    }
    const std::size_t frameFiles = std::string(format) == "obj" ? 12u : 11u;  // + paper.mtl
    if (std::string(format) == "obj" || std::string(format) == "ply") {
      EXPECT_EQ(chunk.size(), frameFiles) << format;
    }
    if (std::string(format) == "gltf") {
      EXPECT_EQ(chunk.count("shot_0040-0050.glb"), 1u);
    }
    if (std::string(format) == "usda") {
      ASSERT_EQ(chunk.count("shot_0040-0050.usda"), 1u);
      const auto samples = usdaSamples(chunk.at("shot_0040-0050.usda"));
      EXPECT_EQ(samples.at("points").size(), 11u);
      EXPECT_EQ(samples.at("faceVertexIndices").front(), 40) << "a chunk starts with a topology";
    }
  }
}

TEST(Export, BadFormatOrRangeIsAnInputErrorNamingTheCachedFrames) {
  TempDir tmp;
  crumple::testing::writeSmallScene(tmp / "scene");
  ASSERT_EQ(runCrumple("simulate " + (tmp / "scene").string() + " --out " + (tmp / "out").string())
                .status,
            0);
  const std::string cache = (tmp / "out/cache.pcache").string();
  auto r = runCrumple("export " + cache + " --format fbx");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("'fbx' is not a format (obj, ply, gltf or usda)"), std::string::npos)
      << r.output;
  r = runCrumple("export " + cache + " --format obj --frames 3-9");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.output.find("--frames 3-9 is outside the cached frames 1-6"), std::string::npos)
      << r.output;
  r = runCrumple("export " + cache + " --format obj --frames 5-x");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_EQ(runCrumple("export " + cache).status, 2) << "--format is required";
  EXPECT_EQ(runCrumple("export " + (tmp / "none.pcache").string() + " --format ply").status, 2);
  EXPECT_FALSE(fs::exists(tmp / "out/export")) << "nothing written on bad input";
  r = runCrumple("export " + cache + " --format ply --frames 2-3");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(fs::exists(tmp / "out/export/ply/0002.ply"));
  EXPECT_TRUE(fs::exists(tmp / "out/export/ply/0003.ply"));
  EXPECT_FALSE(fs::exists(tmp / "out/export/ply/0004.ply"));
  EXPECT_NE(runCrumple("export --help").output.find("--format"), std::string::npos);
}

// An alpha with both a hole (0) and paper (255).
bool hasHoleAndPaper(const ImageRGBA8& image) {
  bool hole = false, paper = false;
  for (std::size_t i = 3; i < image.pixels.size(); i += 4) {
    hole = hole || image.pixels[i] == 0;
    paper = paper || image.pixels[i] == 255;
  }
  return hole && paper;
}

TEST(Export, TornFramesCarryTheirTearTextureAndKeepTheirTwinVertices) {
  TempDir tmp;
  const std::string cachePath = simulateSample("tear-straight", tmp, 17);  // tears at frame 15
  const fs::path dir = fs::path(cachePath).parent_path() / "export";
  for (const char* format : {"obj", "gltf"}) {
    pipeline::ExportOptions options;
    options.format = pipeline::parseExportFormat(format);
    options.log = nullptr;
    (void)pipeline::exportCache(cachePath, options);
  }
  const cache::CacheReader reader(cachePath);
  int torn = 0;
  for (std::size_t i = 0; i < reader.frameCount(); ++i) {
    const cache::FrameRecord f = reader.readFrame(i);
    const std::string s = stem(f.frame);
    const bool tears = cache::decodeTearAtlas(f.extensions).has_value();
    torn += tears ? 1 : 0;
    const fs::path png = dir / "obj" / (s + "_tears.png");
    EXPECT_EQ(fs::exists(png), tears) << s;
    EXPECT_EQ(fs::exists(dir / "obj" / (s + ".mtl")), tears) << s;
    Assimp::Importer importer;
    const aiScene* scene = importer.ReadFile((dir / "obj" / (s + ".obj")).string(), 0u);
    ASSERT_NE(scene, nullptr) << importer.GetErrorString();
    expectFrame(*scene->mMeshes[0], f, s + ".obj");
    aiString texture;
    const aiMaterial& material = *scene->mMaterials[scene->mMeshes[0]->mMaterialIndex];
    EXPECT_EQ(material.GetTexture(aiTextureType_OPACITY, 0, &texture) == AI_SUCCESS, tears) << s;
    if (tears) {
      EXPECT_EQ(std::string(texture.C_Str()), s + "_tears.png");
      const ImageRGBA8 image = exporters::readPng(png.string());  // a valid PNG
      EXPECT_GT(image.width, 100);
      EXPECT_TRUE(hasHoleAndPaper(image)) << s << ": the tear masks cut the paper";
    }
    // glTF keeps the lips' twin vertices (same pattern point) apart.
    Assimp::Importer glb;
    const aiScene* g = glb.ReadFile((dir / "gltf" / (s + ".glb")).string(), 0u);
    ASSERT_NE(g, nullptr) << glb.GetErrorString();
    EXPECT_EQ(g->mMeshes[0]->mNumVertices, f.positions.size()) << s;
    expectFrame(*g->mMeshes[0], f, s + ".glb");
  }
  EXPECT_GE(torn, 3) << "frames 15-17 are torn";
  EXPECT_TRUE(fs::exists(dir / "obj/paper.mtl")) << "shared by the frames before the tear";
}

// The Blender round trip (scripts/blender-roundtrip.sh): Blender imports the
// OBJ, PLY and glTF exports of the crumple shot's first, middle and last
// frames with the cache's counts and bounds, and shows only the frame's node
// of shot.glb at each of them. Runs only with
// CRUMPLE_BLENDER_TESTS=1 and blender on PATH (Blender takes seconds to
// start; the default CI stays fast):
//   CRUMPLE_BLENDER_TESTS=1 ctest --test-dir build -R Export.BlenderRoundTrip -V
TEST(Export, BlenderRoundTripMatchesTheCache) {
  const char* enabled = std::getenv("CRUMPLE_BLENDER_TESTS");
  if (enabled == nullptr || std::string(enabled) != "1")
    GTEST_SKIP() << "set CRUMPLE_BLENDER_TESTS=1 to run the Blender round trip";
  if (crumple::testing::runCommand("command -v blender").status != 0)
    GTEST_SKIP() << "blender is not on PATH";
  TempDir tmp;
  const std::string cachePath = simulateSample("crumple", tmp);
  const auto r =
      crumple::testing::runCommand(std::string("CRUMPLE_BIN=") + CRUMPLE_BIN + " " +
                                   sourcePath("scripts/blender-roundtrip.sh") + " " + cachePath);
  std::printf("%s", r.output.c_str());
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("round trip: 10 imports of 3 frames match the cache"), std::string::npos)
      << r.output;
}

}  // namespace
