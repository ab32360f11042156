#pragma once
// What the whole-shot benchmarks (bench_contacts, bench_tear, bench_sound) share: their
// command line `[SAMPLE ...] [--runs 3] [--json FILE]` and the median.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "crumple/io/scene.hpp"
#include "crumple/pipeline/shot.hpp"

namespace crumple::bench {

struct ShotBenchArgs {
  int runs = 3;
  std::string jsonPath;
  std::vector<std::string> samples;
};

// The command line of benchmark `bench`, its samples `defaults` unless some
// are named; nullopt after printing the usage for --help.
inline std::optional<ShotBenchArgs> parseShotBenchArgs(int argc, char** argv, const char* bench,
                                                       std::vector<std::string> defaults) {
  ShotBenchArgs args;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--runs" && i + 1 < argc) {
      args.runs = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--json" && i + 1 < argc) {
      args.jsonPath = argv[++i];
    } else if (a == "--help" || a == "-h") {
      std::printf("usage: %s [SAMPLE ...] [--runs 3] [--json FILE]\n", bench);
      return std::nullopt;
    } else {
      args.samples.push_back(a);
    }
  }
  if (args.samples.empty()) args.samples = std::move(defaults);
  return args;
}

// printf into a string (a JSON row).
template <typename... Values>
std::string format(const char* pattern, Values... values) {
  char text[512];
  std::snprintf(text, sizeof text, pattern, values...);
  return text;
}

// A scratch folder under the system's temporary folder, removed with it.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& name)
      : path_(std::filesystem::temp_directory_path() / name) {}
  ~ScratchDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  // The folder for one sample's runs.
  std::string operator/(const std::string& sample) const { return (path_ / sample).string(); }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

inline double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n == 0 ? 0.0 : n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// The sample's scene (samples/NAME under the source tree).
inline io::SceneSpec sampleScene(const std::string& name) {
  return io::loadScene(io::resolveScenePath(std::string(CRUMPLE_SOURCE_DIR) + "/samples/" + name));
}

// One quiet simulation of `scene` into `outDir`, without rendering.
inline pipeline::ShotReport simulateQuietly(const io::SceneSpec& scene, const std::string& outDir) {
  pipeline::ShotOptions options;
  options.outDir = outDir;
  options.render = false;
  options.log = nullptr;  // quiet
  options.interactive = 0;
  pipeline::ShotReport report = pipeline::runShot(scene, options);
  return report;
}

// The simulation step's total wall time (ms): the elastic model's and the
// crumpling model's stages and contacts.
inline double stepTotalMs(const pipeline::ShotReport& report) {
  double total = 0.0;
  for (const char* s : {"elastic", "geometric", "cones", "rebuild", "isometry", "contacts"})
    if (const auto it = report.stages.find(s); it != report.stages.end())
      total += it->second.totalMs;
  return total;
}

// Writes {"runs": N, "samples": [ROW, ...]} to the --json path, each row the
// JSON object `toJson` makes of it; nothing without --json. False, with a
// message naming `bench`, when it cannot.
template <typename Row, typename ToJson>
bool writeSampleRows(const ShotBenchArgs& args, const char* bench, const std::vector<Row>& rows,
                     ToJson toJson) {
  if (args.jsonPath.empty()) return true;
  std::FILE* f = std::fopen(args.jsonPath.c_str(), "w");
  if (f == nullptr) {
    std::fprintf(stderr, "%s: cannot write %s\n", bench, args.jsonPath.c_str());
    return false;
  }
  std::fprintf(f, "{\"runs\": %d, \"samples\": [", args.runs);
  for (std::size_t i = 0; i < rows.size(); ++i)
    std::fprintf(f, "%s%s", i == 0 ? "" : ", ", toJson(rows[i]).c_str());
  std::fprintf(f, "]}\n");
  return std::fclose(f) == 0;
}

}  // namespace crumple::bench
