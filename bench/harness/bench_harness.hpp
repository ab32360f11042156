#pragma once
// `crumple bench` (docs/BENCH.md): every sample at its own settings,
// and on the paper's examples the hybrid model at several substep counts and
// isometry length sweeps against the plain elastic model on fixed meshes at
// several resolutions;
// ms per frame by stage beside the error measures. Writes bench.csv,
// pareto.png (gnuplot) and report.md (beside the paper's Tables II-V).
#include <map>
#include <ostream>
#include <string>
#include <vector>

namespace crumple::bench {

struct BenchOptions {
  std::string outDir = "out/bench";
  std::vector<std::string> samples;  // names under samples/ (empty: every sample)
  int runs = 3;                      // timings per configuration (median)
  int lastFrame = -1;                // >= 0: simulate up to this frame at most
  bool quick = false;                // a small subset for tests
  bool projection = true;            // paper Table III (bench/harness/projection_comparison)
  std::string sourceDir;             // the source tree (samples/ under it); empty: the build's
  std::string commandLine;           // quoted in the report
};

// One configuration's result: medians over its runs (the run of median total
// time), the error measures from its cache.
struct BenchRow {
  std::string sample;
  // "own" (the sample's settings), "sweep", or "reference" (a crumpling
  // shot's speed reference and its hybrid pair, over the same first frames)
  std::string role;
  std::string model;    // "hybrid" or "elastic"
  double edgeCm = 0.0;  // the elastic mesh's max edge (0: the hybrid model's adaptive S_P)
  int substeps = 0;
  int lengthSweeps = 0;        // hybrid: the isometry's length sweeps per step (0 for elastic)
  int frames = 0;              // frames simulated
  int runs = 0;                // timed runs
  double trianglesMean = 0.0;  // of the cached mesh, mean over frames
  std::map<std::string, double> msPerFrame;  // stage -> ms/frame
  double msTotal = 0.0;                      // the simulation (every stage but cache, render)
  double newtonPerSubstep = 0.0;
  double cMeanMean = 0.0, cMeanMax = 0.0;    // fractions (paper Table IV, c_mean)
  double nCompMean = 0.0, nCompMax = 0.0;    // fractions (paper Table IV, n_comp)
  double defectMean = 0.0, defectMax = 0.0;  // rad (mean over frames of the mean; max)
  double defectTotal = 0.0;                  // rad: mean over frames of the sum over vertices
  double handleErrorMax = 0.0;               // m
  double poppingMax = 0.0;        // pipeline::poppingMeasure, largest between consecutive frames
  int singularMax = 0;            // singular vertices, most in a frame
  double tearStraightDev = -1.0;  // fraction of the width (tear-straight; < 0: n/a)
  double tearHyperbolaMedian = -1.0, tearHyperbolaP90 = -1.0;  // deg (tear-curved; < 0: n/a)
  std::string status = "ok";                                   // or why the run stopped early
  bool ok() const { return status == "ok"; }
  // e.g. "hybrid x2", "hybrid x1, 3000 sweeps" (away from the default 300),
  // "elastic 0.50 cm x4".
  std::string label() const;
};

// A crumpling shot's speed targets: the hybrid model at most msPerFrame at
// its own settings, and at least minSpeedRatio times faster than the elastic
// model on the fixed kReferenceEdgeCm mesh; that reference runs frames 0 to
// referenceLastFrame of the shot (the bench's budget), and so does its
// hybrid pair.
struct CrumplingTarget {
  std::string sample;
  double msPerFrame = 0.0;
  double minSpeedRatio = 0.0;
  int referenceLastFrame = 0;
  // The Pareto points besides the shot's own settings, over the whole motion:
  // the hybrid model at these substep counts, the elastic model on these
  // meshes (cm) at the shot's substeps.
  std::vector<int> hybridSubsteps;
  std::vector<double> elasticCm;
};
inline constexpr double kReferenceEdgeCm = 0.5;
const std::vector<CrumplingTarget>& crumplingShots();
// The shot's targets, or nullptr when `sample` is not a crumpling shot.
const CrumplingTarget* crumplingShot(const std::string& sample);

// The stage columns of bench.csv, in order.
const std::vector<std::string>& benchStages();

// Runs the benchmark and writes DIR/bench.csv, DIR/pareto.png, DIR/report.md
// (and DIR/table3.csv with the projection comparison). `progress` gets one
// line per run. Throws std::runtime_error (naming what) when an output cannot
// be written or gnuplot is missing; InputError for an unknown sample.
std::vector<BenchRow> runBench(const BenchOptions& options, std::ostream& progress);

// The outputs from rows (exposed for tests).
void writeBenchCsv(const std::string& path, const std::vector<BenchRow>& rows);
// Writes DIR/pareto.gp and DIR/pareto.dat and runs gnuplot into DIR/pareto.png.
void writeParetoPlot(const std::string& dir, const std::vector<BenchRow>& rows);
std::string benchReportMarkdown(const BenchOptions& options, const std::vector<BenchRow>& rows);

}  // namespace crumple::bench
