#pragma once
// What the whole-shot benchmarks (bench_contacts, bench_tear, bench_sound) share: their
// command line `[SAMPLE ...] [--runs 3] [--json FILE]` and the median.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "crumple/io/scene.hpp"
#include "crumple/pipeline/shot.hpp"

namespace crumple::bench {

struct ShotBenchArgs {
  int runs = 3;
  std::string jsonPath;
  std::vector<std::string> samples;  // empty: the benchmark's defaults
  bool help = false;
};

inline ShotBenchArgs parseShotBenchArgs(int argc, char** argv) {
  ShotBenchArgs args;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--runs" && i + 1 < argc) {
      args.runs = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--json" && i + 1 < argc) {
      args.jsonPath = argv[++i];
    } else if (a == "--help" || a == "-h") {
      args.help = true;
    } else {
      args.samples.push_back(a);
    }
  }
  return args;
}

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

// Writes {"runs": N, "samples": [ROW, ...]} to `path` (each row a JSON
// object's text). False, with a message naming `bench`, when it cannot.
inline bool writeSampleRows(const std::string& path, const char* bench, int runs,
                            const std::vector<std::string>& rows) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) {
    std::fprintf(stderr, "%s: cannot write %s\n", bench, path.c_str());
    return false;
  }
  std::fprintf(f, "{\"runs\": %d, \"samples\": [", runs);
  for (std::size_t i = 0; i < rows.size(); ++i)
    std::fprintf(f, "%s%s", i == 0 ? "" : ", ", rows[i].c_str());
  std::fprintf(f, "]}\n");
  return std::fclose(f) == 0;
}

}  // namespace crumple::bench
