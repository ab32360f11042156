// Render-time refinement of the curved regions (developable.hpp): the
// density of the sub-cells, the refined mesh, and the isometry guard.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "crumple/core/index.hpp"
#include "developable_detail.hpp"

namespace crumple::mesh {

double meanLengthError(const SheetMesh& mesh) {
  std::vector<std::pair<int, int>> edges;
  edges.reserve(3 * mesh.triangles.size());
  for (const auto& tri : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const int a = tri[idx(k)], b = tri[idx((k + 1) % 3)];
      edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  std::ranges::sort(edges);
  const auto [first, last] = std::ranges::unique(edges);
  edges.erase(first, last);
  double sum = 0.0;
  std::size_t counted = 0;
  for (const auto& [a, b] : edges) {
    const double rest = (mesh.pattern[idx(a)] - mesh.pattern[idx(b)]).norm();
    if (!(rest > 0.0)) continue;
    sum += std::abs((mesh.positions[idx(a)] - mesh.positions[idx(b)]).norm() - rest) / rest;
    ++counted;
  }
  return counted > 0 ? sum / static_cast<double>(counted) : 0.0;
}

TearAtlas remapTearAtlas(const TearAtlas& atlas, const RefinedSheet& refined) {
  TearAtlas out = atlas;
  for (TearPatch& patch : out.patches) {
    if (!inRange(refined.triangleOfSource, patch.triangle) ||
        refined.triangleOfSource[idx(patch.triangle)] < 0)
      throw std::invalid_argument("remapTearAtlas: the triangle of a tear patch was refined");
    patch.triangle = refined.triangleOfSource[idx(patch.triangle)];
  }
  return out;
}

namespace {

using developable::Run;
using developable::SubRuling;

// A run and its folded strip.
struct FoldedRun {
  Run run;
  int region = -1;
  std::vector<SubRuling> strip;
  double closure = 0.0;  // m
  double width = 0.0;    // m, the run's extent across its rulings in the pattern
  double largestFold = 0.0;
  double sourceFold = 0.0;  // the largest fold of S_P at the run's inner rulings
  int largestCells = 0;
};

// The sub-cells per face of a run in Auto mode: the fold angle between
// neighbouring sub-cells at most options.maxAngle, and with a screen, the
// chord's sagitta w dtheta / (8 N^2) at most options.pixelTolerance pixels
// (w the face's width across its rulings, dtheta its turn).
std::vector<int> autoCells(const SheetMesh& sheet, const Run& run, const RefineOptions& options,
                           const developable::BoundaryCurves& boundary) {
  const std::size_t faces = run.faces.size();
  std::vector<int> cells(faces, 1);
  for (int pass = 0; pass < 12; ++pass) {
    std::vector<SubRuling> strip = developable::subRulings(sheet, run, cells, boundary);
    const developable::FoldResult folded = developable::foldStrip(strip);
    if (!std::isfinite(folded.closure)) break;
    std::vector<double> largest(faces, 0.0), turn(faces, 0.0);
    for (std::size_t j = 1; j + 1 < strip.size(); ++j) {
      const double a = std::abs(folded.angles[j - 1]);
      for (int f : {strip[j].face, strip[j + 1].face}) {
        largest[idx(f)] = std::max(largest[idx(f)], a);
        turn[idx(f)] += 0.5 * a;
      }
    }
    bool changed = false;
    for (std::size_t k = 0; k < faces; ++k) {
      int want = cells[k];
      if (largest[k] > options.maxAngle)
        want = static_cast<int>(std::ceil(cells[k] * largest[k] / options.maxAngle * 1.05));
      if (options.screen) {
        const ScreenMetric& view = *options.screen;
        const developable::Face& f = run.faces[k];
        double depth = std::numeric_limits<double>::infinity();
        for (int v : {f.r0[0], f.r0[1], f.r1[0], f.r1[1]})
          depth = std::min(depth, (sheet.positions[idx(v)] - view.eye).dot(view.forward));
        const double footprint = view.pixelAngle * std::max(view.znear, depth);
        const double width =
            std::max((sheet.pattern[idx(f.r1[0])] - sheet.pattern[idx(f.r0[0])]).norm(),
                     (sheet.pattern[idx(f.r1[1])] - sheet.pattern[idx(f.r0[1])]).norm());
        const double n = std::sqrt(width * turn[k] / (8.0 * options.pixelTolerance * footprint));
        if (std::isfinite(n)) want = std::max(want, static_cast<int>(std::ceil(n)));
      }
      want = std::clamp(want, 1, options.maxCells);
      if (want > cells[k]) {
        cells[k] = want;
        changed = true;
      }
    }
    if (!changed) break;
  }
  return cells;
}

FoldedRun foldRun(const SheetMesh& sheet, Run run, const RefineOptions& options,
                  const developable::BoundaryCurves& boundary) {
  FoldedRun out;
  out.region = sheet.regionOfTriangle[idx(run.faces.front().triangles.front())];
  const std::vector<int> cells =
      options.mode == RefineMode::Fixed
          ? std::vector<int>(run.faces.size(), std::clamp(options.cells, 1, options.maxCells))
          : autoCells(sheet, run, options, boundary);
  for (const double a : developable::foldAngles(
           developable::subRulings(sheet, run, std::vector<int>(run.faces.size(), 1), boundary)))
    out.sourceFold = std::max(out.sourceFold, std::abs(a));
  out.strip = developable::subRulings(sheet, run, cells, boundary);
  const developable::FoldResult folded = developable::foldStrip(out.strip);
  out.closure = folded.closure;
  out.largestFold = folded.largestFold;
  out.largestCells = *std::ranges::max_element(cells);
  for (const auto& f : run.faces)
    out.width += std::max((sheet.pattern[idx(f.r1[0])] - sheet.pattern[idx(f.r0[0])]).norm(),
                          (sheet.pattern[idx(f.r1[1])] - sheet.pattern[idx(f.r0[1])]).norm());
  out.run = std::move(run);
  return out;
}

// The refined mesh with the runs in `chosen` refined: the source's
// triangles outside them in order, then each run's sub-cells (two triangles
// split along the shorter diagonal, one for a fan).
RefinedSheet assemble(const SheetMesh& sheet, const std::vector<FoldedRun>& runs,
                      const std::vector<char>& chosen) {
  RefinedSheet out;
  out.mesh.pattern = sheet.pattern;
  out.mesh.positions = sheet.positions;
  out.mesh.regionTypes = sheet.regionTypes;
  std::vector<char> replaced(sheet.triangleCount(), 0);
  for (std::size_t r = 0; r < runs.size(); ++r)
    if (chosen[r])
      for (const auto& f : runs[r].run.faces)
        for (int t : f.triangles) replaced[idx(t)] = 1;
  out.triangleOfSource.assign(sheet.triangleCount(), -1);
  for (std::size_t t = 0; t < sheet.triangleCount(); ++t) {
    if (replaced[t]) continue;
    out.triangleOfSource[t] = static_cast<int>(out.mesh.triangles.size());
    out.sourceOfTriangle.push_back(static_cast<int>(t));
    out.mesh.triangles.push_back(sheet.triangles[t]);
    out.mesh.regionOfTriangle.push_back(sheet.regionOfTriangle[t]);
  }
  for (std::size_t r = 0; r < runs.size(); ++r) {
    if (!chosen[r]) continue;
    const FoldedRun& fr = runs[r];
    std::vector<std::array<int, 2>> ends;  // vertex of each sub-ruling end
    const int fanSide = fr.run.faces.front().fanSide;
    for (std::size_t j = 0; j < fr.strip.size(); ++j) {
      const SubRuling& s = fr.strip[j];
      std::array<int, 2> e{s.va, s.vb};
      const std::array<const Vec2*, 2> p{&s.pa, &s.pb};
      const std::array<const Vec3*, 2> x{&s.xa, &s.xb};
      const bool border = j == 0 || j + 1 == fr.strip.size();
      for (std::size_t side = 0; side < 2; ++side) {
        if (e[side] < 0) {
          e[side] = static_cast<int>(out.mesh.pattern.size());
          out.mesh.pattern.push_back(*p[side]);
          out.mesh.positions.push_back(*x[side]);
        } else if (!border && static_cast<int>(side) != fanSide) {
          // An inner ruling's free end moves onto the folded surface; the
          // run's border rulings and a fan's apex stay bit for bit.
          out.mesh.positions[idx(e[side])] = *x[side];
        }
      }
      ends.push_back(e);
    }
    for (std::size_t j = 0; j + 1 < ends.size(); ++j) {
      const developable::Face& face = fr.run.faces[idx(fr.strip[j + 1].face)];
      const auto [a0, b0] = ends[j];
      const auto [a1, b1] = ends[j + 1];
      std::vector<std::array<int, 3>> cell;
      if (a0 == a1) {
        cell.push_back({a0, b1, b0});
      } else if (b0 == b1) {
        cell.push_back({a0, a1, b0});
      } else {
        const auto& X = out.mesh.positions;
        if ((X[idx(a0)] - X[idx(b1)]).norm() <= (X[idx(a1)] - X[idx(b0)]).norm())
          cell = {{a0, a1, b1}, {a0, b1, b0}};
        else
          cell = {{a0, a1, b0}, {a1, b1, b0}};
      }
      for (auto tri : cell) {
        if (face.orientation < 0.0) std::swap(tri[1], tri[2]);
        out.mesh.triangles.push_back(tri);
        out.mesh.regionOfTriangle.push_back(fr.region);
        out.sourceOfTriangle.push_back(-1);
      }
    }
  }
  return out;
}

}  // namespace

RefinedSheet refineDevelopable(const SheetMesh& sheet, const DevelopableStructure& structure,
                               const RefineOptions& options, std::span<const int> pinned,
                               std::span<const int> locked) {
  const double sourceError = meanLengthError(sheet);
  std::vector<FoldedRun> runs;
  RefineStats stats;
  stats.regions = static_cast<int>(structure.regions.size());
  if (options.mode != RefineMode::Off && !structure.regions.empty()) {
    if (const std::string problem = validate(structure, sheet); !problem.empty())
      throw std::invalid_argument("refineDevelopable: " + problem);
    std::vector<char> pinnedVertex(sheet.vertexCount(), 0),
        lockedTriangle(sheet.triangleCount(), 0);
    for (int v : pinned)
      if (inRange(pinnedVertex, v)) pinnedVertex[idx(v)] = 1;
    for (int t : locked)
      if (inRange(lockedTriangle, t)) lockedTriangle[idx(t)] = 1;
    const developable::BoundaryCurves boundary(sheet, pinnedVertex);
    const auto trianglesOfVertex = developable::trianglesOfVertices(sheet);
    std::vector<std::vector<int>> regionTriangles(sheet.regionTypes.size());
    for (std::size_t t = 0; t < sheet.triangleCount(); ++t)
      if (inRange(regionTriangles, sheet.regionOfTriangle[t]))
        regionTriangles[idx(sheet.regionOfTriangle[t])].push_back(static_cast<int>(t));
    for (const CurvedRegion& region : structure.regions) {
      const auto faces = developable::regionFaces(
          sheet, region, regionTriangles[idx(region.region)], boundary, lockedTriangle);
      stats.skippedFaces += static_cast<int>(
          std::ranges::count_if(faces, [](const auto& f) { return !f.refinable; }));
      for (Run& run : developable::regionRuns(faces, trianglesOfVertex, pinnedVertex))
        runs.push_back(foldRun(sheet, std::move(run), options, boundary));
    }
  }
  // A run is refined when its folds came out finite and smooth (within
  // maxAngle, or at most half S_P's sharpest fold there: a closure the folds
  // cannot reach otherwise bends a few sub-cells hard); then the guard.
  std::vector<char> chosen(runs.size(), 0);
  for (std::size_t r = 0; r < runs.size(); ++r) {
    const FoldedRun& run = runs[r];
    chosen[r] = std::isfinite(run.closure) &&
                (run.largestFold <= options.maxAngle || run.largestFold <= 0.5 * run.sourceFold);
    stats.roughRuns += chosen[r] ? 0 : 1;
  }
  RefinedSheet out = assemble(sheet, runs, chosen);
  double refinedError = meanLengthError(out.mesh);
  while (refinedError > sourceError + options.lengthBudget) {
    // The isometry guard: the run with the largest closure per width goes back.
    int worst = -1;
    for (std::size_t r = 0; r < runs.size(); ++r)
      if (chosen[r] && (worst < 0 || runs[r].closure / runs[r].width >
                                         runs[idx(worst)].closure / runs[idx(worst)].width))
        worst = static_cast<int>(r);
    if (worst < 0) break;
    chosen[idx(worst)] = 0;
    ++stats.guardedRuns;
    out = assemble(sheet, runs, chosen);
    refinedError = meanLengthError(out.mesh);
  }
  stats.runs = static_cast<int>(runs.size());
  for (std::size_t r = 0; r < runs.size(); ++r) {
    if (!chosen[r]) continue;
    ++stats.refinedRuns;
    stats.largestCells = std::max(stats.largestCells, runs[r].largestCells);
    stats.largestFold = std::max(stats.largestFold, runs[r].largestFold);
    stats.largestClosure = std::max(stats.largestClosure, runs[r].closure);
  }
  stats.lengthErrorSource = sourceError;
  stats.lengthErrorRefined = refinedError;
  out.stats = stats;
  return out;
}

}  // namespace crumple::mesh
