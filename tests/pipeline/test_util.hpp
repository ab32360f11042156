#pragma once
// Helpers for scene-level tests: temporary folders, running the CLI, files.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace crumple::testing {

namespace fs = std::filesystem;

// Tests of several minutes each run only with CRUMPLE_LONG_TESTS=1
// (scripts/test-long.sh), keeping the default suite within its budget.
#define CRUMPLE_LONG_TEST()                                                                 \
  do {                                                                                      \
    const char* long_tests = std::getenv("CRUMPLE_LONG_TESTS");                             \
    if (long_tests == nullptr || std::string(long_tests) != "1")                            \
      GTEST_SKIP() << "a long test: runs with CRUMPLE_LONG_TESTS=1 (scripts/test-long.sh)"; \
  } while (false)

// A fresh folder under the system temp dir, removed at the end of the test.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() / (std::string("crumple-") + info->test_suite_name() + "-" +
                                         info->name() + "-" + std::to_string(::getpid()));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::permissions(path_, fs::perms::owner_all, fs::perm_options::add, ec);
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }
  fs::path operator/(const std::string& name) const { return path_ / name; }

 private:
  fs::path path_;
};

struct CommandResult {
  int status = -1;
  std::string output;  // stdout and stderr together
};

inline CommandResult runCommand(const std::string& command) {
  CommandResult r;
  std::FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return r;
  std::array<char, 4096> buf{};
  while (std::fgets(buf.data(), static_cast<int>(buf.size()), pipe) != nullptr)
    r.output += buf.data();
  const int raw = ::pclose(pipe);
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return r;
}

inline CommandResult runCrumple(const std::string& args) {
  return runCommand(std::string(CRUMPLE_BIN) + " " + args);
}

inline std::string readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline void writeFile(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
}

inline std::string sourcePath(const std::string& rel) {
  return (fs::path(CRUMPLE_SOURCE_DIR) / rel).string();
}

}  // namespace crumple::testing

#include <cstdint>
#include <cstring>
#include <vector>

namespace crumple::testing {

inline std::string base64(const std::vector<std::uint8_t>& data) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < data.size(); i += 3) {
    std::uint32_t n = static_cast<std::uint32_t>(data[i]) << 16;
    if (i + 1 < data.size()) n |= static_cast<std::uint32_t>(data[i + 1]) << 8;
    if (i + 2 < data.size()) n |= data[i + 2];
    out += table[(n >> 18) & 63];
    out += table[(n >> 12) & 63];
    out += i + 1 < data.size() ? table[(n >> 6) & 63] : '=';
    out += i + 2 < data.size() ? table[n & 63] : '=';
  }
  return out;
}

// A glTF 2.0 file with one node per track, each with linear translation keys
// (float32, as every exporter writes them). Nodes without keys are static.
struct GltfTrack {
  std::string node;
  std::vector<float> times;
  std::vector<std::array<float, 3>> positions;
  std::vector<std::array<float, 4>> rotations = {};  // x, y, z, w at `times` (optional)
};
inline std::string makeGltf(const std::vector<GltfTrack>& tracks) {
  std::vector<std::uint8_t> blob;
  std::string views, accessors, samplers, channels, nodes;
  int accessor = 0;
  auto append = [&](const void* p, std::size_t n, int count, const char* type, bool minmax,
                    float lo, float hi) {
    const std::size_t offset = blob.size();
    blob.resize(offset + n);
    std::memcpy(blob.data() + offset, p, n);
    if (!views.empty()) views += ",";
    views += "{\"buffer\":0,\"byteOffset\":" + std::to_string(offset) +
             ",\"byteLength\":" + std::to_string(n) + "}";
    if (!accessors.empty()) accessors += ",";
    accessors += "{\"bufferView\":" + std::to_string(accessor) +
                 ",\"componentType\":5126,\"count\":" + std::to_string(count) + ",\"type\":\"" +
                 type + "\"";
    if (minmax)
      accessors += ",\"min\":[" + std::to_string(lo) + "],\"max\":[" + std::to_string(hi) + "]";
    accessors += "}";
    return accessor++;
  };
  int sampler = 0;
  for (std::size_t i = 0; i < tracks.size(); ++i) {
    const auto& t = tracks[i];
    const auto& p0 = t.positions.empty() ? std::array<float, 3>{0, 0, 0} : t.positions[0];
    if (!nodes.empty()) nodes += ",";
    nodes += "{\"name\":\"" + t.node + "\",\"translation\":[" + std::to_string(p0[0]) + "," +
             std::to_string(p0[1]) + "," + std::to_string(p0[2]) + "]}";
    if (t.times.size() < 2) continue;
    const int in = append(t.times.data(), t.times.size() * 4, static_cast<int>(t.times.size()),
                          "SCALAR", true, t.times.front(), t.times.back());
    const int out = append(t.positions.data(), t.positions.size() * 12,
                           static_cast<int>(t.positions.size()), "VEC3", false, 0, 0);
    if (!samplers.empty()) samplers += ",";
    samplers += "{\"input\":" + std::to_string(in) + ",\"output\":" + std::to_string(out) +
                ",\"interpolation\":\"LINEAR\"}";
    if (!channels.empty()) channels += ",";
    channels += "{\"sampler\":" + std::to_string(sampler++) +
                ",\"target\":{\"node\":" + std::to_string(i) + ",\"path\":\"translation\"}}";
    if (t.rotations.size() != t.times.size()) continue;
    const int rot = append(t.rotations.data(), t.rotations.size() * 16,
                           static_cast<int>(t.rotations.size()), "VEC4", false, 0, 0);
    samplers += ",{\"input\":" + std::to_string(in) + ",\"output\":" + std::to_string(rot) +
                ",\"interpolation\":\"LINEAR\"}";
    channels += ",{\"sampler\":" + std::to_string(sampler++) +
                ",\"target\":{\"node\":" + std::to_string(i) + ",\"path\":\"rotation\"}}";
  }
  std::string roots;
  for (std::size_t i = 0; i < tracks.size(); ++i) {
    if (i > 0) roots += ',';
    roots += std::to_string(i);
  }
  std::string g = "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[" + roots +
                  "]}],\"nodes\":[" + nodes + "]";
  if (!samplers.empty()) {
    g += ",\"animations\":[{\"samplers\":[" + samplers + "],\"channels\":[" + channels + "]}]";
    g += ",\"buffers\":[{\"byteLength\":" + std::to_string(blob.size()) +
         ",\"uri\":\"data:application/octet-stream;base64," + base64(blob) + "\"}]";
    g += ",\"bufferViews\":[" + views + "],\"accessors\":[" + accessors + "]";
  }
  return g + "}\n";
}

}  // namespace crumple::testing

namespace crumple::testing {

// A small, fast shot: a 10 x 10 cm sheet hanging from two top corners that
// move apart and together, 6 frames, 160 x 120 preview.
inline std::string smallSceneToml(const std::string& extraSheet = "",
                                  const std::string& animation = "anim.gltf") {
  return "[scene]\nname = \"small\"\nunits = \"cm\"\nfps = 24\nframes = [1, 6]\nsubsteps = 2\n"
         "seed = 7\nanimation = \"" +
         animation +
         "\"\n"
         "[sheet]\nwidth = 10.0\nheight = 10.0\nmax_edge = 2.5\norigin = [-5.0, 10.0, 0.0]\n"
         "u_axis = [1.0, 0.0, 0.0]\nv_axis = [0.0, 1.0, 0.0]\n" +
         extraSheet +
         "[paper]\npreset = \"office-70gsm\"\n"
         "[[handles]]\nname = \"left\"\nnode = \"A\"\npattern = [0.0, 10.0]\n"
         "[[handles]]\nname = \"right\"\nnode = \"B\"\npattern = [10.0, 10.0]\n"
         "[camera]\nposition = [0.0, 15.0, 40.0]\nlook_at = [0.0, 14.0, 0.0]\nfov_deg = 40\n"
         "resolution = [160, 120]\n"
         "[ground]\nenabled = true\nheight = 0.0\nsize = 60.0\n";
}

inline std::string smallAnimation(float nanAt = 0.0f) {
  GltfTrack a{"A",
              {0.0f, 0.1f, 0.25f},
              {{-0.05f, 0.20f, 0.0f}, {-0.06f, 0.20f, 0.01f}, {-0.04f, 0.21f, 0.0f}}};
  GltfTrack b{"B",
              {0.0f, 0.1f, 0.25f},
              {{0.05f, 0.20f, 0.0f}, {0.06f, 0.20f, 0.01f}, {0.04f, 0.21f, 0.0f}}};
  if (nanAt != 0.0f) a.positions[1][1] = nanAt;
  return makeGltf({a, b});
}

inline void writeSmallScene(const fs::path& dir) {
  fs::create_directories(dir);
  writeFile(dir / "scene.toml", smallSceneToml());
  writeFile(dir / "anim.gltf", smallAnimation());
}

}  // namespace crumple::testing

namespace crumple::testing {
// A measured value for RecordProperty (gtest XML): scientific notation.
inline std::string sci(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3e", v);
  return buf;
}
}  // namespace crumple::testing

namespace crumple::testing {

// `crumple simulate ARGS --threads N --out DIR/N` for N = 1 and 2 (ARGS:
// the scene and any options); the two caches' bytes, each run's exit
// status checked.
inline std::array<std::string, 2> cachesOnOneAndTwoThreads(const std::string& args,
                                                           const TempDir& dir) {
  std::array<std::string, 2> caches;
  for (const int threads : {1, 2}) {
    const std::string out = (dir / std::to_string(threads)).string();
    const auto r =
        runCrumple("simulate " + args + " --threads " + std::to_string(threads) + " --out " + out);
    EXPECT_EQ(r.status, 0) << r.output;
    caches[static_cast<std::size_t>(threads - 1)] = readFile(out + "/cache.pcache");
  }
  return caches;
}

}  // namespace crumple::testing

namespace crumple::testing {

// A glTF with one mesh node "Cup" (a triangle) whose translation moves from
// (0, 0, 0) at t = 0 to (1, 0, 0) at t = 1 s.
inline std::string movingPropGltf() {
  std::vector<std::uint8_t> buf;
  auto putF = [&](float f) {
    std::uint8_t b[4];
    std::memcpy(b, &f, 4);
    buf.insert(buf.end(), b, b + 4);
  };
  for (const float f : {0.f, 0.f, 0.f, 0.1f, 0.f, 0.f, 0.f, 0.1f, 0.f}) putF(f);  // 36 bytes
  for (const std::uint16_t i : {std::uint16_t{0}, std::uint16_t{1}, std::uint16_t{2},
                                std::uint16_t{0}}) {  // 8 bytes (padded)
    buf.push_back(static_cast<std::uint8_t>(i & 0xff));
    buf.push_back(static_cast<std::uint8_t>(i >> 8));
  }
  for (const float f : {0.f, 1.f}) putF(f);                      // times: 8 bytes at 44
  for (const float f : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f}) putF(f);  // translations: 24 bytes at 52
  return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
  "nodes": [{"name": "Cup", "mesh": 0}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
  "buffers": [{"byteLength": )" +
         std::to_string(buf.size()) + R"(, "uri": "data:application/octet-stream;base64,)" +
         base64(buf) + R"("}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                  {"buffer": 0, "byteOffset": 36, "byteLength": 6},
                  {"buffer": 0, "byteOffset": 44, "byteLength": 8},
                  {"buffer": 0, "byteOffset": 52, "byteLength": 24}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                 "min": [0, 0, 0], "max": [0.1, 0.1, 0]},
                {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"},
                {"bufferView": 2, "componentType": 5126, "count": 2, "type": "SCALAR",
                 "min": [0], "max": [1]},
                {"bufferView": 3, "componentType": 5126, "count": 2, "type": "VEC3"}],
  "animations": [{"channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}],
                  "samplers": [{"input": 2, "output": 3, "interpolation": "LINEAR"}]}]})";
}

}  // namespace crumple::testing
