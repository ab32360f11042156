#pragma once
// What the whole-shot benchmarks (bench_contacts, bench_tear) share: their
// command line `[SAMPLE ...] [--runs 3] [--json FILE]` and the median.
#include <algorithm>
#include <cstdlib>
#include <string>
#include <vector>

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

}  // namespace crumple::bench
