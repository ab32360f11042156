// Paper Table III standalone: the isometry projection (Sec. 6.3) against a
// hard-constraint Shape-Up projection on the inputs the crumpling model hands
// the projection in the hybrid samples (bench/harness/projection_comparison).
//
//   build/bench/bench_projection [--runs 5] [--csv FILE] [sample ...]
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

#include "projection_comparison.hpp"

int main(int argc, char** argv) {
  int runs = 5;
  std::string csv;
  std::vector<std::string> samples;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--runs" && i + 1 < argc) {
      runs = std::atoi(argv[++i]);
    } else if (a == "--csv" && i + 1 < argc) {
      csv = argv[++i];
    } else if (a == "--help" || a == "-h") {
      std::puts("bench_projection [--runs 5] [--csv FILE] [sample ...]");
      return 0;
    } else {
      samples.push_back(a);
    }
  }
  if (samples.empty())
    samples = {"cylinder-fold", "first-singularity", "unload", "moebius", "crumple"};
  const auto rows =
      crumple::bench::compareProjections(samples, runs, CRUMPLE_SOURCE_DIR, &std::cerr);
  std::cout << crumple::bench::projectionComparisonMarkdown(rows);
  if (!csv.empty()) crumple::bench::writeProjectionComparisonCsv(csv, rows);
  return 0;
}
