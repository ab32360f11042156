// crumple-bench: speed against error (docs/BENCH.md), `crumple bench`'s
// program. The bench harness lives here, outside the production binary.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <iostream>
#include <sstream>
#include <string>

#include "bench_harness.hpp"
#include "crumple/core/error.hpp"
#include "crumple/core/exit_status.hpp"

int main(int argc, char** argv) {
  using namespace crumple;
  CLI::App app{
      "Speed against error (docs/BENCH.md): every sample at its own settings, and on the "
      "paper's examples (cylinder-fold, first-singularity, unload, moebius) the "
      "hybrid model at 1, 2, 4, 8 substeps, and at 1 and 2 with 1000, 3000, 10000 and 30000 "
      "isometry length sweeps, against the elastic model on fixed 2 and 1 cm "
      "meshes at 1, 2, 4 substeps, 0.5 cm at 2 and 4, and on first-singularity (Table II) "
      "0.25 cm at 2; ms per frame by "
      "stage beside c_mean, n_comp, angle defect, handle error and the tear errors. One "
      "thread. Writes DIR/bench.csv, DIR/pareto.png (gnuplot) with each model's Pareto "
      "front, DIR/report.md beside the paper's Tables II-V (and DIR/table3.csv). About 20 "
      "minutes with the defaults (30 at most)."};
  app.name("crumple bench");
  bench::BenchOptions options;
  std::string samples;
  bool noProjection = false;
  app.add_option("--out", options.outDir, "output folder")->capture_default_str();
  app.add_option("--samples", samples,
                 "a,b,...: sample names under samples/ (paper-types/eps-0.5.toml for a "
                 "variant; default: every sample)");
  app.add_option("--runs", options.runs,
                 "timed runs per configuration, the median reported (a run over 10 s is "
                 "timed once)")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  app.add_option("--frames", options.lastFrame,
                 "LAST: simulate every configuration up to frame LAST at most");
  app.add_flag("--quick", options.quick,
               "a small subset for tests: first-singularity and drape up to frame 24 (or "
               "--frames), one run, the hybrid model at 1 and 2 substeps, elastic 2 and "
               "1 cm meshes at 2");
  app.add_flag("--no-projection", noProjection,
               "skip paper Table III (the isometry projection against Shape-Up)");
  app.add_option("--source", options.sourceDir,
                 "the source tree whose samples/ are run (default: this build's)");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return e.get_exit_code() == 0 ? app.exit(e) : (app.exit(e), 2);
  }
  return runWithExitStatus("crumple bench", [&] {
    std::string name;
    for (std::istringstream in(samples); std::getline(in, name, ',');)
      if (!name.empty()) options.samples.push_back(name);
    options.projection = !noProjection;
    options.commandLine = "crumple bench";
    for (int i = 1; i < argc; ++i) options.commandLine += std::string(" ") + argv[i];
    bench::runBench(options, std::cerr);
    std::printf("report: %s/report.md\n  csv:   %s/bench.csv\n  plot:  %s/pareto.png\n",
                options.outDir.c_str(), options.outDir.c_str(), options.outDir.c_str());
    return 0;
  });
}
