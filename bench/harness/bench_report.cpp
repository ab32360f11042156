// `crumple bench`: its outputs, bench.csv, pareto.png (gnuplot) and report.md
// (docs/BENCH.md "Outputs").
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "bench_harness.hpp"
#include "pareto.hpp"

namespace fs = std::filesystem;

namespace crumple::bench {

namespace {

std::string num(double v, const char* format = "%.6g") {
  char text[64];
  std::snprintf(text, sizeof text, format, v);
  return text;
}

// A CSV field: quoted when it holds a comma, a quote or a line break.
std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (const char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' ? ' ' : c);
  return q + "\"";
}

double stageMs(const BenchRow& r, const std::string& stage) {
  const auto it = r.msPerFrame.find(stage);
  return it == r.msPerFrame.end() ? 0.0 : it->second;
}

// The error measures a Pareto front is drawn for, and the report's verdicts.
struct Measure {
  const char* name;  // in the report and the plot
  const char* unit;
  double scale;  // of the stored value into `unit`
  std::function<double(const BenchRow&)> of;
};
const std::vector<Measure>& paretoMeasures() {
  static const std::vector<Measure> measures = {
      {"c_mean (mean over frames)", "%", 100.0, [](const BenchRow& r) { return r.cMeanMean; }},
      {"angle defect, total (mean over frames)", "rad", 1.0,
       [](const BenchRow& r) { return r.defectTotal; }},
  };
  return measures;
}

// The samples with elastic sweep rows (the Pareto samples), in row order.
std::vector<std::string> sweepSamples(const std::vector<BenchRow>& rows) {
  std::vector<std::string> names;
  for (const BenchRow& r : rows)
    if (r.role == "sweep" && std::find(names.begin(), names.end(), r.sample) == names.end())
      names.push_back(r.sample);
  return names;
}

// One model's points of a Pareto sample for a measure: every finished
// configuration (the sample's own settings included).
std::vector<ParetoPoint> points(const std::vector<BenchRow>& rows, const std::string& sample,
                                const std::string& model, const Measure& m) {
  std::vector<ParetoPoint> p;
  for (const BenchRow& r : rows)
    if (r.sample == sample && r.model == model && r.ok() && r.role != "reference")
      p.push_back({m.scale * m.of(r), r.msTotal, r.label()});
  return p;
}

const BenchRow* findRow(const std::vector<BenchRow>& rows, const std::string& sample,
                        const std::function<bool(const BenchRow&)>& pick) {
  for (const BenchRow& r : rows)
    if (r.sample == sample && pick(r)) return &r;
  return nullptr;
}

// The paper's examples and our samples for them (Tables IV and V).
struct PaperExample {
  const char* figure;
  const char* sample;             // "" when no sample reproduces it
  double cMean, nComp;            // Table IV (%)
  int nt, ns, nit;                // Table V
  double tInt, tCol, tRem, tIso;  // Table V (ms)
  const char* why;
};
const std::vector<PaperExample>& paperExamples() {
  static const std::vector<PaperExample> examples = {
      {"Fig. 1", "cylinder-fold", 0.89, 8.0, 118, 2, 5, 117, 25, 0.4, 1.0,
       "the cylindrical wrap, then the fold (Sec. 7.3)"},
      {"Fig. 18 (top)", "moebius", 0.17, 0.1, 117, 0, 11, 232, 62, 0.2, 3.1,
       "the strip twisted until its ends meet"},
      {"Fig. 18 (bottom)", "unload", 0.19, 2.0, 87, 1, 4, 50, 10, 0.4, 1.0,
       "the sheet folded, then released (Sec. 7.1)"},
      {"Fig. 22 (2nd row)", "crumple", 1.47, 11, 156, 15, 5, 190, 57, 0.5, 2.3,
       "the full crumpling with many singular vertices"},
      {"Fig. 22 (4th row)", "", 0.20, 2.0, 120, 21, 8, 190, 48, 0.8, 0.9,
       "interactive play with the handles: no scripted motion to reproduce"},
  };
  return examples;
}

std::string orDash(const BenchRow* r, const std::function<std::string(const BenchRow&)>& f) {
  return r ? f(*r) : std::string("-");
}

// The crumpling shots against their speed targets (docs/BENCH.md "The
// crumpling shots").
void crumplingShotsMarkdown(const std::vector<BenchRow>& rows, std::ostream& md) {
  bool any = false;
  for (const CrumplingTarget& t : crumplingShots())
    any = any || findRow(rows, t.sample, [](const BenchRow& r) { return r.role == "own"; });
  if (!any) return;
  md << "## The crumpling shots\n\n"
     << "crumple and crumple-ball have their own rows on the Pareto fronts above. Their speed "
     << "targets: the hybrid model at its own settings within the ms per frame below, and at "
     << "least the given ratio faster than the elastic model on a fixed "
     << num(kReferenceEdgeCm, "%.2f") << " cm mesh running the same motion. That reference "
     << "runs the shot's first frames only (the bench's budget), and the hybrid model runs "
     << "the same frames beside it for the ratio. A reference that stops earlier says where "
     << "and why in its status. The largest handle error is where a handle lags under the "
     << "strain bound (`[model] max_edge_strain`): the fronts above weigh lengths and "
     << "developability, not how far the sheet follows its handles.\n\n"
     << "| shot | hybrid, own settings: ms/frame (target) | its largest handle error, mm "
     << "| reference: frames, ms/frame, status | hybrid on the reference's frames: ms/frame "
     << "| speed ratio (target) |\n"
     << "| --- | --- | --- | --- | --- | --- |\n";
  for (const CrumplingTarget& t : crumplingShots()) {
    const BenchRow* own =
        findRow(rows, t.sample, [](const BenchRow& r) { return r.role == "own"; });
    if (!own) continue;
    const BenchRow* ref = findRow(rows, t.sample, [](const BenchRow& r) {
      return r.role == "reference" && r.model == "elastic";
    });
    const BenchRow* pair = findRow(rows, t.sample, [](const BenchRow& r) {
      return r.role == "reference" && r.model == "hybrid";
    });
    const auto met = [](bool ok) { return ok ? std::string("met") : std::string("not met"); };
    md << "| " << t.sample << " | " << num(own->msTotal, "%.1f")
       << " (<= " << num(t.msPerFrame, "%.0f") << ": "
       << met(own->ok() && own->msTotal <= t.msPerFrame) << ") | "
       << num(1e3 * own->handleErrorMax, "%.1f") << " | ";
    if (ref)
      md << ref->frames << " of the shot's " << own->frames << " frames, "
         << num(ref->msTotal, "%.0f") << ", " << ref->status;
    else
      md << "not run";
    md << " | " << (pair ? num(pair->msTotal, "%.1f") : std::string("-")) << " | ";
    if (ref && pair && pair->msTotal > 0.0 && ref->msTotal > 0.0) {
      const double ratio = ref->msTotal / pair->msTotal;
      md << num(ratio, "%.1f") << "x (>= " << num(t.minSpeedRatio, "%.0f")
         << "x: " << met(ratio >= t.minSpeedRatio) << ")";
    } else {
      md << "-";
    }
    md << " |\n";
  }
  md << "\n";
}

}  // namespace

void writeBenchCsv(const std::string& path, const std::vector<BenchRow>& rows) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  out << "sample,role,model,edge_cm,substeps,length_sweeps,triangles_mean,frames,runs";
  for (std::string s : benchStages()) {
    std::replace(s.begin(), s.end(), ' ', '_');  // "contact check" -> ms_contact_check
    out << ",ms_" << s;
  }
  out << ",ms_total,newton_per_substep,c_mean_mean_pct,c_mean_max_pct,n_comp_mean_pct,"
         "n_comp_max_pct,angle_defect_mean_rad,angle_defect_max_rad,angle_defect_total_rad,"
         "handle_error_max_m,popping_max,"
         "singular_max,tear_straight_dev_pct,tear_hyperbola_median_deg,tear_hyperbola_p90_deg,"
         "status\n";
  const auto optional = [](double v, double scale) {
    return v < 0.0 ? std::string() : num(scale * v);
  };
  for (const BenchRow& r : rows) {
    out << csvField(r.sample) << ',' << r.role << ',' << r.model << ','
        << (r.model == "hybrid" ? std::string() : num(r.edgeCm)) << ',' << r.substeps << ','
        << (r.model == "hybrid" ? std::to_string(r.lengthSweeps) : std::string()) << ','
        << num(r.trianglesMean) << ',' << r.frames << ',' << r.runs;
    for (const std::string& s : benchStages()) out << ',' << num(stageMs(r, s));
    out << ',' << num(r.msTotal) << ',' << num(r.newtonPerSubstep) << ',' << num(100 * r.cMeanMean)
        << ',' << num(100 * r.cMeanMax) << ',' << num(100 * r.nCompMean) << ','
        << num(100 * r.nCompMax) << ',' << num(r.defectMean) << ',' << num(r.defectMax) << ','
        << num(r.defectTotal) << ',' << num(r.handleErrorMax) << ',' << num(r.poppingMax) << ','
        << r.singularMax << ',' << optional(r.tearStraightDev, 100) << ','
        << optional(r.tearHyperbolaMedian, 1) << ',' << optional(r.tearHyperbolaP90, 1) << ','
        << csvField(r.status) << '\n';
  }
  if (!out) throw std::runtime_error("cannot write " + path);
}

void writeParetoPlot(const std::string& dir, const std::vector<BenchRow>& rows) {
  if (std::system("command -v gnuplot >/dev/null 2>&1") != 0)
    throw std::runtime_error(
        "gnuplot is not installed: `crumple bench` draws pareto.png with it (Debian: "
        "gnuplot-nox; bash scripts/bootstrap.sh installs it)");
  const fs::path base = fs::absolute(dir);
  const std::vector<std::string> samples = sweepSamples(rows);
  // pareto.dat: per panel four blocks (hybrid points, elastic points, their fronts).
  std::ofstream data(base / "pareto.dat");
  std::ostringstream plots;
  constexpr double kFloor = 1e-9;  // a zero error, drawn on the log scale
  int index = 0;
  for (const std::string& sample : samples)
    for (const Measure& m : paretoMeasures()) {
      const auto hybrid = points(rows, sample, "hybrid", m);
      const auto elastic = points(rows, sample, "elastic", m);
      for (const auto* set : {&hybrid, &elastic}) {
        for (const std::vector<ParetoPoint>& block : {*set, paretoFront(*set)}) {
          data << "# " << sample << " " << m.name << "\n";
          for (const ParetoPoint& p : block)
            data << num(std::max(p.error, kFloor)) << ' ' << num(p.ms) << " \"" << p.label
                 << "\"\n";
          if (block.empty()) data << "nan nan \"\"\n";
          data << "\n\n";
        }
      }
      plots << "set title '" << sample << ": " << m.name << "'\n"
            << "set xlabel '" << m.name << " (" << m.unit << ")'\n"
            << "plot D index " << index
            << " with points pt 7 ps 1.2 lc rgb '#d62728' title 'hybrid',"
            << " D index " << index + 1 << " with lines lw 2 lc rgb '#d62728' title 'hybrid front',"
            << " D index " << index + 2
            << " with points pt 5 ps 1.0 lc rgb '#1f77b4' title 'elastic',"
            << " D index " << index + 3
            << " with lines lw 2 dt 2 lc rgb '#1f77b4' title 'elastic front'\n";
      index += 4;
    }
  data.close();
  if (!data) throw std::runtime_error("cannot write " + (base / "pareto.dat").string());
  const int rowsOfPanels = std::max<int>(1, static_cast<int>(samples.size()));
  std::ofstream gp(base / "pareto.gp");
  gp << "# Written by `crumple bench` (docs/BENCH.md): ms per frame against error, each\n"
     << "# model's configurations and its Pareto front; zero errors drawn at " << kFloor << ".\n"
     << "set terminal pngcairo size 1400," << 420 * rowsOfPanels << " font ',10'\n"
     << "set output '" << (base / "pareto.png").string() << "'\n"
     << "D = '" << (base / "pareto.dat").string() << "'\n"
     << "set termoption noenhanced\nset logscale xy\nset grid\nset key outside right top\nset "
        "ylabel 'ms "
        "per frame'\n"
     << "set multiplot layout " << rowsOfPanels << "," << paretoMeasures().size() << "\n";
  if (samples.empty())
    gp << "set title 'no sweep sample was run'\nunset logscale\nplot [0:1][0:1] 0 notitle\n";
  gp << plots.str() << "unset multiplot\n";
  gp.close();
  if (!gp) throw std::runtime_error("cannot write " + (base / "pareto.gp").string());
  const std::string command = "gnuplot '" + (base / "pareto.gp").string() + "'";
  if (std::system(command.c_str()) != 0)
    throw std::runtime_error("gnuplot failed on " + (base / "pareto.gp").string());
}

std::string benchReportMarkdown(const BenchOptions& options, const std::vector<BenchRow>& rows) {
  std::ostringstream md;
  md << "# Speed against error (`crumple bench`)\n\n"
     << "Written by `" << options.commandLine << "` (docs/BENCH.md); nothing here is typed by "
     << "hand. One thread; per configuration the median of up to "
     << (options.quick ? 1 : options.runs)
     << " runs in one process (a run longer than 10 s is timed once; `runs` in bench.csv). "
     << "ms per frame is the simulation's (every stage but writing the cache and rendering). "
     << "The errors are measured on the cached frames as `crumple inspect` does: c_mean = mean "
     << "|l - L| / L over edges, n_comp = share of edges compressed by more than 1 %, angle "
     << "defect = |2 pi - sum of corner angles| at interior vertices that are not singular (its "
     << "mean and max per vertex, and its total over the vertices: the mean and max shrink "
     << "with the mesh's triangles, the total converges to the integral of |K|, so the "
     << "Pareto fronts use the total).\n\n";

  md << "## The Pareto verdict\n\n"
     << "Each model's points are its finished configurations on the sample: the hybrid model "
     << "at several substep counts and isometry length sweeps (`[model] "
     << "isometry_length_sweeps`: the Gauss-Seidel edge-length sweeps after the isometry "
     << "projection's Phase II, 300 by default; a label without sweeps is at 300), the plain "
     << "elastic model on fixed meshes (max edge in cm) "
     << "at several substep counts (`pareto.png`). At each error level of the elastic front, "
     << "the cheapest hybrid point at that error or better and the speed ratio elastic / "
     << "hybrid. **Below** means the hybrid model is faster at every level.\n\n"
     << "| sample | measure | verdict | speed ratios at the elastic front's levels |\n"
     << "| --- | --- | --- | --- |\n";
  for (const std::string& sample : sweepSamples(rows))
    for (const Measure& m : paretoMeasures()) {
      const ParetoVerdict v =
          paretoVerdict(points(rows, sample, "hybrid", m), points(rows, sample, "elastic", m));
      std::string ratios;
      for (const VerdictLevel& l : v.levels)
        ratios += (ratios.empty() ? "" : ", ") + (l.hybrid ? num(l.ratio, "%.2f") + "x" : "none");
      md << "| " << sample << " | " << m.name << " | "
         << (v.levels.empty() ? "no elastic front"
             : v.below        ? "**below**"
                              : "not below")
         << " | " << (ratios.empty() ? "-" : ratios) << " |\n";
    }
  md << "\n";
  for (const std::string& sample : sweepSamples(rows))
    for (const Measure& m : paretoMeasures()) {
      const ParetoVerdict v =
          paretoVerdict(points(rows, sample, "hybrid", m), points(rows, sample, "elastic", m));
      if (v.levels.empty()) {
        md << "### " << sample << ", " << m.name << ": no elastic front\n\n"
           << "No elastic configuration finished the shot (see \"Every configuration\").\n\n";
        continue;
      }
      md << "### " << sample << ", " << m.name << ": " << (v.below ? "below" : "not below")
         << "\n\n"
         << "| elastic front point | error (" << m.unit << ") | ms/frame | cheapest hybrid at "
         << "that error or better | error (" << m.unit << ") | ms/frame | speed ratio |\n"
         << "| --- | --- | --- | --- | --- | --- | --- |\n";
      for (const VerdictLevel& l : v.levels) {
        md << "| " << l.elastic.label << " | " << num(l.elastic.error, "%.3g") << " | "
           << num(l.elastic.ms, "%.1f") << " | ";
        if (l.hybrid)
          md << l.hybrid->label << " | " << num(l.hybrid->error, "%.3g") << " | "
             << num(l.hybrid->ms, "%.1f") << " | " << num(l.ratio, "%.2f") << "x |\n";
        else
          md << "none reaches it | - | - | - |\n";
      }
      md << "\n";
    }

  crumplingShotsMarkdown(rows, md);

  // Table II: the Sec. 7.1 experiment (Fig. 19) is first-singularity.
  md << "## Paper Table II (Fig. 19)\n\n"
     << "Fig. 19 runs \"the example used in the experiment of Sec. 7.1\": our `first-singularity`. "
     << "The paper's standard FEM is a dense fixed mesh \"to obtain visually sharp features\" "
     << "(here the 0.25 cm mesh), its coarse FEM a fixed mesh at about the crumpling model's "
     << "cost (here the elastic configuration whose ms per frame is nearest the hybrid "
     << "model's). Remeshing is the S_P rebuild; simulation is the rest of the step. "
     << "Narain et al.'s adaptive remeshing is not implemented. ms per frame.\n\n";
  {
    const std::string s = "first-singularity";
    const BenchRow* own = findRow(rows, s, [](const BenchRow& r) { return r.role == "own"; });
    const BenchRow* dense = findRow(rows, s, [&](const BenchRow& r) {
      return r.model == "elastic" && r.edgeCm == 0.25 && r.substeps == 2;
    });
    const BenchRow* coarse = nullptr;
    if (own)
      for (const BenchRow& r : rows)
        if (r.sample == s && r.model == "elastic" && r.ok() && r.msTotal > 0.0 &&
            (!coarse || std::abs(std::log(r.msTotal / own->msTotal)) <
                            std::abs(std::log(coarse->msTotal / own->msTotal))))
          coarse = &r;
    const auto rem = [](const BenchRow& r) { return num(stageMs(r, "rebuild"), "%.2f"); };
    const auto sim = [](const BenchRow& r) {
      return num(r.msTotal - stageMs(r, "rebuild"), "%.1f");
    };
    const auto tri = [](const BenchRow& r) { return num(r.trianglesMean, "%.0f"); };
    const auto head = [](const BenchRow* r) { return r ? r->label() : std::string("not run"); };
    md << "| | paper: our method | paper: standard FEM | paper: coarse FEM | paper: Narain et al. "
       << "| paper: coarse Narain | ours: " << head(own) << " | ours: " << head(dense)
       << " | ours: " << head(coarse)
       << " |\n| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n"
       << "| remeshing | 1 | - | - | 450 | 30 | " << orDash(own, rem) << " | - | - |\n"
       << "| simulation | 100 | 14 700 | 340 | 4 640 | 480 | " << orDash(own, sim) << " | "
       << orDash(dense, sim) << " | " << orDash(coarse, sim) << " |\n"
       << "| triangles | 89 | 1 668 | 212 | 788 | 221 | " << orDash(own, tri) << " | "
       << orDash(dense, tri) << " | " << orDash(coarse, tri) << " |\n";
    if (own && dense && own->msTotal > 0.0)
      md << "\nThe dense mesh costs " << num(dense->msTotal / own->msTotal, "%.1f")
         << "x the crumpling model (paper: 14 700 / (100 + 1) = 145.5x).\n";
    md << "\n";
  }

  md << "## Paper Table IV\n\n"
     << "Paper: c_mean is the mean compression over the edges, averaged over the frames; "
     << "n_comp the share of edges compressed by more than 1 %. Ours: c_mean = mean |l - L| / L "
     << "(stretch counts too, so it is stricter), each at the sample's own settings.\n\n"
     << "| paper example | our sample (why) | paper c_mean % | ours: mean over frames | worst "
     << "frame | paper n_comp % | ours: mean over frames | worst frame |\n"
     << "| --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (const PaperExample& e : paperExamples()) {
    const BenchRow* r = findRow(rows, e.sample, [](const BenchRow& x) { return x.role == "own"; });
    std::string sample = "none";
    if (*e.sample) sample = std::string("`").append(e.sample).append("`");
    md << "| " << e.figure << " | " << sample << " (" << e.why << ") | " << num(e.cMean) << " | "
       << orDash(r, [](const BenchRow& x) { return num(100 * x.cMeanMean, "%.3f"); }) << " | "
       << orDash(r, [](const BenchRow& x) { return num(100 * x.cMeanMax, "%.3f"); }) << " | "
       << num(e.nComp) << " | "
       << orDash(r, [](const BenchRow& x) { return num(100 * x.nCompMean, "%.2f"); }) << " | "
       << orDash(r, [](const BenchRow& x) { return num(100 * x.nCompMax, "%.2f"); }) << " |\n";
  }

  md << "\n## Paper Table V\n\n"
     << "N_t: triangles (paper: of S_P; ours: of the cached mesh, mean over frames), N_s: "
     << "singular vertices (paper: interior, at most; ours: most in a frame), N_it: Newton "
     << "iterations per step, t_int: the elastic step, t_col: contacts (ours: self-contact; "
     << "these samples have no colliders), t_rem: remeshing (our S_P rebuild), t_iso: the isometry "
        "projection; ms per "
     << "frame, each paper / ours.\n\n"
     << "| paper example | our sample | N_t | N_s | N_it | t_int | t_col | t_rem | t_iso |\n"
     << "| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (const PaperExample& e : paperExamples()) {
    const BenchRow* r = findRow(rows, e.sample, [](const BenchRow& x) { return x.role == "own"; });
    const auto pair = [&](double paper, const std::function<std::string(const BenchRow&)>& f) {
      return num(paper) + " / " + orDash(r, f);
    };
    md << "| " << e.figure << " | " << (*e.sample ? e.sample : "none") << " | "
       << pair(e.nt, [](const BenchRow& x) { return num(x.trianglesMean, "%.0f"); }) << " | "
       << pair(e.ns, [](const BenchRow& x) { return std::to_string(x.singularMax); }) << " | "
       << pair(e.nit, [](const BenchRow& x) { return num(x.newtonPerSubstep, "%.1f"); }) << " | "
       << pair(e.tInt, [](const BenchRow& x) { return num(stageMs(x, "elastic"), "%.2f"); })
       << " | "
       << pair(e.tCol, [](const BenchRow& x) { return num(stageMs(x, "contacts"), "%.2f"); })
       << " | "
       << pair(e.tRem, [](const BenchRow& x) { return num(stageMs(x, "rebuild"), "%.2f"); })
       << " | "
       << pair(e.tIso, [](const BenchRow& x) { return num(stageMs(x, "isometry"), "%.2f"); })
       << " |\n";
  }

  md << "\n## Every configuration\n\n"
     << "| sample | role | configuration | triangles | frames | runs | ms/frame | c_mean % mean "
     << "/ worst | n_comp % worst | angle defect rad: mean / max / total | handle error mm | tear "
        "error | "
     << "status |\n| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- "
        "|\n";
  for (const BenchRow& r : rows) {
    std::string tear = "-";
    if (r.tearStraightDev >= 0.0) tear = num(100 * r.tearStraightDev, "%.2f") + " % of the width";
    if (r.tearHyperbolaMedian >= 0.0)
      tear = num(r.tearHyperbolaMedian, "%.1f") + " deg median, " +
             num(r.tearHyperbolaP90, "%.1f") + " deg 90 %";
    md << "| " << r.sample << " | " << r.role << " | " << r.label() << " | "
       << num(r.trianglesMean, "%.0f") << " | " << r.frames << " | " << r.runs << " | "
       << num(r.msTotal, "%.2f") << " | " << num(100 * r.cMeanMean, "%.3f") << " / "
       << num(100 * r.cMeanMax, "%.3f") << " | " << num(100 * r.nCompMax, "%.2f") << " | "
       << num(r.defectMean, "%.3g") << " / " << num(r.defectMax, "%.3g") << " / "
       << num(r.defectTotal, "%.3g") << " | " << num(1e3 * r.handleErrorMax, "%.3g") << " | "
       << tear << " | " << r.status << " |\n";
  }
  return md.str();
}

}  // namespace crumple::bench
