// `crumple bench`: the runs (docs/BENCH.md "What is run").
#include "bench_harness.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <optional>
#include <set>
#include <stdexcept>

#include "../json_number.hpp"
#include "../shot_bench.hpp"
#include "crumple/cache/pcache.hpp"
#include "crumple/core/error.hpp"
#include "crumple/core/parallel.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/pipeline/inspect.hpp"
#include "crumple/pipeline/shot.hpp"
#include "crumple/pipeline/tear_measures.hpp"
#include "projection_comparison.hpp"

namespace fs = std::filesystem;

namespace crumple::bench {

namespace {

// The paper's examples (Tables II, IV, V) on which the two models' Pareto
// fronts are measured; crumple (Fig. 22) and crumple-ball have a plan of
// their own (crumplingShots). paper-types shares cylinder-fold's motion,
// wiggle has no paper figure, tear-cylinder hands a torn sheet over to the
// elastic model.
const std::vector<std::string> kSweepSamples = {"cylinder-fold", "first-singularity", "unload",
                                                "moebius"};
// A run longer than this is timed once (its noise is small against its length).
constexpr double kSlowRunSeconds = 10.0;

// What the sweeps run (chosen to fit about 30 minutes; docs/BENCH.md).
struct ElasticMesh {
  double edgeCm;
  std::vector<int> substeps;
  std::string onlySample;  // non-empty: on this sample only
};
struct SweepPlan {
  std::vector<int> hybridSubsteps;  // at the sample's length sweeps
  // The isometry's length sweeps (`[model] isometry_length_sweeps`), each at
  // every count of hybridSweepSubsteps: the hybrid model's accuracy knob.
  std::vector<int> hybridLengthSweeps;
  std::vector<int> hybridSweepSubsteps;
  std::vector<ElasticMesh> elastic;
  bool crumplingShots = true;  // their Pareto points and speed reference
};

SweepPlan sweepPlan(bool quick) {
  if (quick) return {{1, 2}, {3000}, {1}, {{2.0, {2}, ""}, {1.0, {2}, ""}}, false};
  // The 0.5 cm mesh at one substep needs many halvings (cylinder-fold: 1.5 s per
  // frame); the 0.25 cm mesh stands for the paper's dense FEM of Table II only.
  return {{1, 2, 4, 8},
          {1000, 3000, 10000, 30000},
          {1, 2},
          {{2.0, {1, 2, 4}, ""},
           {1.0, {1, 2, 4}, ""},
           {0.5, {2, 4}, ""},
           {0.25, {2}, "first-singularity"}},
          true};
}

std::vector<std::string> allSamples(const fs::path& samplesDir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(samplesDir)) {
    if (!entry.is_directory()) continue;
    const std::string name = entry.path().filename().string();
    if (fs::exists(entry.path() / "scene.toml")) {
      names.push_back(name);
    } else {  // a folder of variants (paper-types/*.toml)
      for (const auto& f : fs::directory_iterator(entry.path()))
        if (f.path().extension() == ".toml")
          names.push_back(name + "/" + f.path().filename().string());
    }
  }
  std::sort(names.begin(), names.end());
  return names;
}

// A planned configuration: the scene to run and its row's identity.
struct Config {
  io::SceneSpec scene;
  BenchRow row;
  double weight = 1.0;  // estimated cost, for the ETA
};

// The sample (its scene and own row) on the hybrid model at `substeps` and
// `lengthSweeps` isometry length sweeps (0: the sample's).
Config hybridAt(const io::SceneSpec& scene, const BenchRow& own, int substeps,
                const std::string& role, int lengthSweeps = 0) {
  Config c{scene, own, 1.0};
  c.scene.substeps = substeps;
  c.row.role = role;
  c.row.substeps = substeps;
  if (lengthSweeps > 0) {
    c.scene.crumpling.isometryLengthSweeps = lengthSweeps;
    c.row.lengthSweeps = lengthSweeps;
  }
  return c;
}

// The same motion on the elastic model's fixed mesh of `edgeCm`.
Config elasticAt(const io::SceneSpec& scene, const BenchRow& own, double edgeCm, int substeps,
                 const std::string& role) {
  Config c{scene, own, 1.0};
  c.scene.model.type = io::ModelSpec::Type::Elastic;
  c.scene.sheet.maxEdge = edgeCm / 100.0;
  c.scene.substeps = substeps;
  c.row.role = role;
  c.row.model = "elastic";
  c.row.edgeCm = edgeCm;
  c.row.lengthSweeps = 0;
  c.row.substeps = substeps;
  return c;
}

double meshEdge(const io::SceneSpec& s) {
  return s.sheet.maxEdge > 0.0 ? s.sheet.maxEdge : std::min(s.sheet.width, s.sheet.height) / 16.0;
}

// Estimated cost: frames x substeps x triangles (S_P holds about 150), and
// for the hybrid model the length sweeps.
double estimateWeight(const io::SceneSpec& s) {
  const double frames = static_cast<double>(s.frameEnd - s.frameStart + 1);
  double triangles = 150.0;
  if (s.model.type == io::ModelSpec::Type::Elastic) {
    const double e = meshEdge(s);
    triangles = std::max(50.0, 2.0 * std::ceil(s.sheet.width / e) * std::ceil(s.sheet.height / e));
  }
  // The isometry's length sweeps dominate a hybrid step beyond a few
  // thousand (moebius at one substep: 2.4 ms per frame at 300, 40 at 30000).
  const double sweeps = s.model.type == io::ModelSpec::Type::Hybrid
                            ? static_cast<double>(s.crumpling.isometryLengthSweeps)
                            : 0.0;
  return frames * s.substeps * triangles * (1.0 + sweeps / 2000.0);
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return -1.0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

// The error measures of every cached frame (pipeline::measureFrame).
void measureCache(const std::string& cachePath, BenchRow& row) {
  const cache::CacheReader reader(cachePath);
  const std::size_t n = reader.frameCount();
  double triangles = 0.0, cMean = 0.0, nComp = 0.0, defect = 0.0, total = 0.0;
  std::optional<cache::FrameRecord> previous;
  for (std::size_t i = 0; i < n; ++i) {
    cache::FrameRecord frame = reader.readFrame(i);
    const pipeline::FrameMetrics m = pipeline::measureFrame(frame);
    if (previous)
      row.poppingMax = std::max(row.poppingMax, pipeline::poppingMeasure(*previous, frame));
    previous = std::move(frame);
    triangles += static_cast<double>(m.triangles);
    cMean += m.cMean;
    nComp += m.nComp;
    defect += m.meanAngleDefect;
    total += m.totalAngleDefect;
    row.cMeanMax = std::max(row.cMeanMax, m.cMean);
    row.nCompMax = std::max(row.nCompMax, m.nComp);
    row.defectMax = std::max(row.defectMax, m.maxAngleDefect);
    row.handleErrorMax = std::max(row.handleErrorMax, m.handleError);
    row.singularMax = std::max(row.singularMax, static_cast<int>(m.singularVertices));
  }
  if (n > 0) {
    const double k = static_cast<double>(n);
    row.trianglesMean = triangles / k;
    row.cMeanMean = cMean / k;
    row.nCompMean = nComp / k;
    row.defectMean = defect / k;
    row.defectTotal = total / k;
  }
  row.frames = static_cast<int>(n);
}

// The tear path's errors of the two tear samples with a prediction.
void measureTear(const std::string& sample, const pipeline::ShotReport& report, BenchRow& row) {
  const std::vector<Vec2> tips = pipeline::tearTips(report);
  if (tips.size() < 2) return;
  if (sample == "tear-straight") {
    row.tearStraightDev = pipeline::straightTearDeviation(tips, pipeline::kTearStraightBisectorU) /
                          pipeline::kTearStraightWidth;
  } else if (sample == "tear-curved") {
    const auto errors = pipeline::hyperbolaAngleErrors(tips, pipeline::kTearCurvedPullA,
                                                       pipeline::kTearCurvedPullB);
    row.tearHyperbolaMedian = percentile(errors, 0.5);
    row.tearHyperbolaP90 = percentile(errors, 0.9);
  }
}

std::string readText(const fs::path& p) {
  std::ifstream in(p);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// One simulation of the configuration into `dir`: its row with the timings
// and (measure = true) the error measures.
BenchRow runOnce(const Config& c, const fs::path& dir, bool measure) {
  fs::remove_all(dir);
  BenchRow row = c.row;
  pipeline::ShotReport report;
  try {
    report = simulateQuietly(c.scene, dir.string());
  } catch (const NumericalError& e) {
    // The cache holds the frames up to the last good one, the summary their costs.
    row.status = std::string("stopped: ") + e.what();
    const std::string text = readText(dir / "summary.json");
    const std::size_t at = text.find("\"ms_per_frame\"");
    const std::string summary =  // that object only
        at == std::string::npos ? std::string() : text.substr(at, text.find('}', at) - at);
    for (const std::string& stage : benchStages())
      if (const double ms = jsonNumber(summary, stage, 0.0); ms > 0.0) {
        row.msPerFrame[stage] = ms;
        row.msTotal += ms;
      }
  } catch (const InputError& e) {
    // e.g. the 2 cm mesh holds one vertex for two handles: no such configuration.
    row.status = std::string("not run: ") + e.what();
  }
  if (row.ok()) {
    for (const auto& [name, cost] : report.stages) {
      if (name == "cache" || name == "render" || name == "sound") continue;
      row.msPerFrame[name] = cost.msPerFrame();
      row.msTotal += cost.msPerFrame();
    }
    if (report.substeps > 0)
      row.newtonPerSubstep =
          static_cast<double>(report.newtonIterations) / static_cast<double>(report.substeps);
    measureTear(c.row.sample, report, row);
  }
  if (measure && fs::exists(dir / "cache.pcache"))
    measureCache((dir / "cache.pcache").string(), row);
  return row;
}

std::string fileSafe(std::string s) {
  for (char& ch : s)
    if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '-' && ch != '.') ch = '_';
  return s;
}

}  // namespace

// The crumpling shots, with their speed targets (docs/BENCH.md "The crumpling
// shots"): on the Pareto fronts like the paper's examples, and timed against
// the elastic model on a fixed 0.5 cm mesh running the same frames.
const std::vector<CrumplingTarget>& crumplingShots() {
  // Chosen to fit the bench's budget (docs/BENCH.md "The crumpling shots"):
  // the reference's last frame (the 0.5 cm mesh takes 2-30 s per frame on
  // these motions), and crumple-ball's points (its hybrid model took 5.1 s
  // per frame at 8 substeps, its 1 cm mesh ran over 15 min without finishing).
  static const std::vector<CrumplingTarget> shots = {{"crumple", 10.0, 20.0, 36, {2, 8}, {1.0}},
                                                     {"crumple-ball", 50.0, 20.0, 12, {2}, {2.0}}};
  return shots;
}
const CrumplingTarget* crumplingShot(const std::string& sample) {
  for (const CrumplingTarget& t : crumplingShots())
    if (t.sample == sample) return &t;
  return nullptr;
}

std::string BenchRow::label() const {
  char text[64];
  if (model == "hybrid" && lengthSweeps != paper::CrumpleParams{}.isometryLengthSweeps)
    std::snprintf(text, sizeof text, "hybrid x%d, %d sweeps", substeps, lengthSweeps);
  else if (model == "hybrid")
    std::snprintf(text, sizeof text, "hybrid x%d", substeps);
  else
    std::snprintf(text, sizeof text, "elastic %.2f cm x%d", edgeCm, substeps);
  return text;
}

const std::vector<std::string>& benchStages() {
  static const std::vector<std::string> stages = {
      "elastic",  "geometric",     "cones", "rebuild",      "isometry",  "strain limit",
      "contacts", "contact check", "tear",  "sound events", "checkpoint"};
  return stages;
}

namespace {

// A crumpling shot's configurations: the hybrid model and the elastic model
// at the shot's Pareto points over the whole motion, then the speed
// reference: the elastic model on the fixed 0.5 cm mesh and the hybrid model
// at its own settings, both over frames 0..referenceLastFrame (role
// "reference", left out of the fronts).
void addCrumplingShot(const io::SceneSpec& scene, const BenchRow& own, const CrumplingTarget& shot,
                      const SweepPlan& plan, int lastFrame,
                      const std::function<void(Config)>& add) {
  if (!plan.crumplingShots) return;  // --quick: the shot's own row only
  for (const int s : shot.hybridSubsteps) add(hybridAt(scene, own, s, "sweep"));
  for (const double cm : shot.elasticCm) add(elasticAt(scene, own, cm, scene.substeps, "sweep"));
  int last = scene.frameStart + shot.referenceLastFrame;
  if (lastFrame >= 0) last = std::min(last, lastFrame);
  for (Config c : {elasticAt(scene, own, kReferenceEdgeCm, scene.substeps, "reference"),
                   hybridAt(scene, own, scene.substeps, "reference")}) {
    c.scene.frameEnd = std::min(c.scene.frameEnd, last);
    add(std::move(c));
  }
}

}  // namespace

std::vector<BenchRow> runBench(const BenchOptions& options, std::ostream& progress) {
  setThreadCount(1);  // ratios compare like with like
  const std::string sourceDir =
      options.sourceDir.empty() ? std::string(CRUMPLE_SOURCE_DIR) : options.sourceDir;
  const fs::path samplesDir = fs::path(sourceDir) / "samples";
  std::vector<std::string> samples = options.samples;
  if (samples.empty())
    samples = options.quick ? std::vector<std::string>{"first-singularity", "drape"}
                            : allSamples(samplesDir);
  const int runs = options.quick ? 1 : std::max(1, options.runs);
  const int lastFrame = options.quick && options.lastFrame < 0 ? 24 : options.lastFrame;
  const SweepPlan plan = sweepPlan(options.quick);

  // The plan: each sample at its own settings, then the sweeps.
  std::vector<Config> configs;
  std::set<std::string> planned;
  const auto add = [&](Config c) {
    // A reference runs fewer frames than the row of the same label.
    const std::string key =
        c.row.sample + "|" + c.row.label() + (c.row.role == "reference" ? "|reference" : "");
    if (!planned.insert(key).second) return;  // the own settings already hold it
    if (lastFrame >= 0) c.scene.frameEnd = std::min(c.scene.frameEnd, lastFrame);
    c.weight = estimateWeight(c.scene);
    configs.push_back(std::move(c));
  };
  for (const std::string& name : samples) {
    const io::SceneSpec scene = io::loadScene(io::resolveScenePath((samplesDir / name).string()));
    const bool hybrid = scene.model.type == io::ModelSpec::Type::Hybrid;
    BenchRow own;
    own.sample = name;
    own.role = "own";
    own.model = hybrid ? "hybrid" : "elastic";
    own.edgeCm = hybrid ? 0.0 : 100.0 * meshEdge(scene);
    own.substeps = scene.substeps;
    own.lengthSweeps = hybrid ? scene.crumpling.isometryLengthSweeps : 0;
    add(Config{scene, own, 1.0});
    if (const CrumplingTarget* shot = crumplingShot(name); hybrid && shot) {
      addCrumplingShot(scene, own, *shot, plan, lastFrame, add);
      continue;
    }
    if (!hybrid ||
        std::find(kSweepSamples.begin(), kSweepSamples.end(), name) == kSweepSamples.end())
      continue;
    for (const int s : plan.hybridSubsteps) add(hybridAt(scene, own, s, "sweep"));
    for (const int sweeps : plan.hybridLengthSweeps)
      for (const int s : plan.hybridSweepSubsteps) add(hybridAt(scene, own, s, "sweep", sweeps));
    for (const ElasticMesh& mesh : plan.elastic)
      if (mesh.onlySample.empty() || mesh.onlySample == name)
        for (const int s : mesh.substeps) add(elasticAt(scene, own, mesh.edgeCm, s, "sweep"));
  }

  const fs::path outDir = options.outDir;
  fs::create_directories(outDir);
  const fs::path work = outDir / "runs";
  double totalWeight = 0.0, doneWeight = 0.0;
  for (const Config& c : configs) totalWeight += c.weight;
  const auto start = std::chrono::steady_clock::now();
  const auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  std::vector<BenchRow> rows;
  for (std::size_t i = 0; i < configs.size(); ++i) {
    const Config& c = configs[i];
    const fs::path dir = work / fileSafe(c.row.sample + "-" + c.row.label());
    std::vector<BenchRow> timed;
    for (int r = 0; r < runs; ++r) {
      const double before = elapsed();
      timed.push_back(runOnce(c, dir, r == 0));
      const double seconds = elapsed() - before;
      // The ETA: the weight done so far, this configuration's share by runs.
      const double done = doneWeight + c.weight * (r + 1) / runs;
      const double eta = done > 0.0 ? elapsed() * (totalWeight - done) / done : 0.0;
      char line[512];
      std::snprintf(line, sizeof line,
                    "bench [%zu/%zu] %s, %s, run %d/%d: %.1f ms/frame, %.1f s; %.0f s elapsed, "
                    "about %.0f s to go%s\n",
                    i + 1, configs.size(), c.row.sample.c_str(), c.row.label().c_str(), r + 1, runs,
                    timed.back().msTotal, seconds, elapsed(), std::max(0.0, eta),
                    timed.back().ok() ? "" : ("; " + timed.back().status).c_str());
      progress << line;
      if (seconds > kSlowRunSeconds || !timed.back().ok()) break;
    }
    // The run of median total time, with the first run's error measures.
    std::vector<std::size_t> order(timed.size());
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
    std::sort(order.begin(), order.end(),
              [&](std::size_t a, std::size_t b) { return timed[a].msTotal < timed[b].msTotal; });
    BenchRow row = timed.front();
    const BenchRow& median = timed[order[order.size() / 2]];
    row.msPerFrame = median.msPerFrame;
    row.msTotal = median.msTotal;
    row.runs = static_cast<int>(timed.size());
    // Paths relative to the source tree, so that the report reads the same anywhere.
    for (std::size_t at; (at = row.status.find(sourceDir + "/")) != std::string::npos;)
      row.status.erase(at, sourceDir.size() + 1);
    rows.push_back(row);
    doneWeight += c.weight;
    fs::remove_all(dir);
  }
  fs::remove_all(work);

  writeBenchCsv((outDir / "bench.csv").string(), rows);
  writeParetoPlot(outDir.string(), rows);
  std::string report = benchReportMarkdown(options, rows);
  if (options.projection) {
    // The samples that stand for Table III's examples (crumple included: its
    // projection inputs exist even though the elastic model cannot run it).
    std::vector<std::string> projectionSamples;
    for (const std::string& s : samples)
      if (std::find(kSweepSamples.begin(), kSweepSamples.end(), s) != kSweepSamples.end() ||
          s == "crumple")
        projectionSamples.push_back(s);
    progress << "bench: paper Table III, the isometry projection against Shape-Up\n";
    const auto table3 = compareProjections(projectionSamples, runs, sourceDir, &progress);
    writeProjectionComparisonCsv((outDir / "table3.csv").string(), table3);
    report += "\n" + projectionComparisonMarkdown(table3);
  } else {
    report += "\n## Paper Table III\n\nNot run (`--no-projection`).\n";
  }
  std::ofstream out(outDir / "report.md");
  out << report;
  if (!out) throw std::runtime_error("cannot write " + (outDir / "report.md").string());
  progress << "bench: done in " << static_cast<long>(elapsed())
           << " s: " << (outDir / "report.md").string() << ", bench.csv, pareto.png\n";
  return rows;
}

}  // namespace crumple::bench
