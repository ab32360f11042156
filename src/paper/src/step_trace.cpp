#include "step_trace.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "crumple/core/debug.hpp"
#include "crumple/core/index.hpp"

namespace crumple::paper::detail {

int stepTraceLevel() { return debugOptions().geometry; }

double maxHingeAngle(const sim::ElasticSheet& elastic) {
  double out = 0.0;
  for (std::size_t h = 0; h < elastic.hinges().size(); ++h)
    out = std::max(out, std::abs(elastic.hingeAngle(h)));
  return out;
}

void printStepTrace(int level, int frame, const GeometricMesh& sg, const PhysicalMesh& sp,
                    const sim::ElasticSheet& elastic, const HybridStepStats& stats,
                    const std::vector<sim::Pin>& pinned, const std::array<double, 3>& hinge,
                    double elasticStrain) {
  // Developer trace of the geometric step, one line per frame.
  int curved = 0;
  for (const Region& r : sg.regions) curved += r.type == mesh::RegionType::Curved ? 1 : 0;
  const GeometricStepStats& gs = stats.geometric;
  std::fprintf(stderr,
               "[geometry] frame %d: S_G %zu v %zu f %zu regions (%d curved), S_P %zu tris; "
               "flips %d splits %d "
               "curved+ %d singular+ %d creases %d junction %d flattened %d cmax %.4f; c_mean "
               "%.2e -> %.2e\n",
               frame, sg.vertices.size(), sg.faces.size(), sg.regions.size(), curved,
               sp.mesh.triangleCount(), gs.edgeFlips, gs.flatSplits, gs.curvedCreated,
               gs.singularInserted, gs.creases, gs.junctionMoves, gs.curvedFlattened,
               gs.maxCompression, stats.isometry.meanLengthErrorBefore,
               stats.isometry.meanLengthErrorAfter);
  double vmax = 0.0;
  for (const Vec3& vv : elastic.velocities()) vmax = std::max(vmax, vv.norm());
  // Worst S_P triangle in the pattern: 4 sqrt(3) area / sum of squared edges (1: equilateral).
  double quality = 1.0;
  std::array<int, 3> worst{0, 0, 0};
  for (const auto& tri : sp.mesh.triangles) {
    const Vec2& a = sp.mesh.pattern[idx(tri[0])];
    const Vec2& b = sp.mesh.pattern[idx(tri[1])];
    const Vec2& c = sp.mesh.pattern[idx(tri[2])];
    const Vec2 ab = b - a;
    const Vec2 ac = c - a;
    const double area = 0.5 * (ab.x() * ac.y() - ab.y() * ac.x());
    const double sum = ab.squaredNorm() + ac.squaredNorm() + (c - b).squaredNorm();
    if (4.0 * std::sqrt(3.0) * area / sum < quality) {
      quality = 4.0 * std::sqrt(3.0) * area / sum;
      worst = tri;
    }
  }
  double maxHinge = 0.0;
  Vec2 maxHingeAt = Vec2::Zero();
  for (std::size_t h = 0; h < elastic.hinges().size(); ++h) {
    const double a = std::abs(elastic.hingeAngle(h));
    if (a > maxHinge) {
      maxHinge = a;
      const auto& e = elastic.hinges()[h];
      maxHingeAt = 0.5 * (sp.mesh.pattern[idx(e.v[0])] + sp.mesh.pattern[idx(e.v[1])]);
    }
  }
  std::fprintf(
      stderr,
      "[geometry]   max speed %.3g m/s, isometry displacement %.3g m (Phase I %d, sweeps %d), "
      "Newton %d (%d solves), halvings %d, max hinge %.3f rad at (%.2f, %.2f cm) [%.3f %.3f %.3f], "
      "worst S_P triangle "
      "%.3g",
      vmax, stats.isometry.meanDisplacement, stats.isometry.phaseOneIterations,
      stats.isometry.lengthSweeps, stats.elastic.newtonIterations, stats.elastic.solves,
      stats.elastic.halvings, maxHinge, 100 * maxHingeAt.x(), 100 * maxHingeAt.y(), hinge[0],
      hinge[1], hinge[2], quality);
  for (int k : worst) {
    const Vec2& p = sp.mesh.pattern[idx(k)];
    std::fprintf(stderr, " %d%s(%.2f, %.2f cm)", k, inRange(sg.vertices, k) ? "g" : "", 100 * p.x(),
                 100 * p.y());
  }
  // Max edge strain as the elastic step left S_P, and the strain limit's
  // view of the last step (before -> after, the handles' largest lag).
  const StrainLimitStats& lim = stats.strainLimit;
  std::fprintf(stderr, "; edge strain elastic %.4f, limit %.4f -> %.4f, lag %.3g m%s",
               elasticStrain, lim.maxBefore, lim.maxAfter, lim.lag,
               lim.carried ? " (carried)" : "");
  std::fprintf(stderr, "\n");
  if (level == 3) {  // the worst edges at the step's end (isometry, strain limit, contacts)
    std::vector<char> isPinned(sp.mesh.vertexCount(), 0);
    for (const auto& p : pinned) isPinned[idx(p.vertex)] = 1;
    std::vector<std::pair<double, std::array<int, 2>>> errs;
    for (const auto& e : mesh::buildEdges(sp.mesh)) {
      const auto a = idx(e.v[0]);
      const auto b = idx(e.v[1]);
      const double l0 = (sp.mesh.pattern[a] - sp.mesh.pattern[b]).norm();
      const double l = (sp.mesh.positions[a] - sp.mesh.positions[b]).norm();
      errs.push_back({(l - l0) / l0, e.v});
    }
    std::sort(errs.begin(), errs.end(),
              [](const auto& x, const auto& y) { return std::abs(x.first) > std::abs(y.first); });
    for (std::size_t k = 0; k < std::min<std::size_t>(8, errs.size()); ++k) {
      std::fprintf(stderr, "[geometry]   edge err %+.4f:", errs[k].first);
      for (int v : errs[k].second) {
        const Vec2& p = sp.mesh.pattern[idx(v)];
        std::fprintf(stderr, " %d%s%s(%.2f, %.2f cm)", v, inRange(sg.vertices, v) ? "g" : "",
                     isPinned[idx(v)] ? "P" : "", 100 * p.x(), 100 * p.y());
      }
      std::fprintf(stderr, "\n");
    }
  }
  if (level == 2) {  // S_G itself
    for (std::size_t i = 0; i < sg.vertices.size(); ++i) {
      const GeometricVertex& gv = sg.vertices[i];
      std::fprintf(stderr, "[geometry]   v %zu (%.3f, %.3f cm)%s%s%s%s\n", i, 100 * gv.pattern.x(),
                   100 * gv.pattern.y(), gv.onBoundary ? " boundary" : "",
                   gv.corner ? " corner" : "", gv.singular ? " singular" : "",
                   gv.handle ? " handle" : "");
    }
    for (std::size_t f = 0; f < sg.faces.size(); ++f) {
      const GeometricFace& gf = sg.faces[f];
      std::fprintf(stderr, "[geometry]   f %zu: %d %d %d %d region %d %s\n", f, gf.v[0], gf.v[1],
                   gf.v[2], gf.v[3], gf.region,
                   sg.regions[idx(gf.region)].type == mesh::RegionType::Curved ? "curved" : "flat");
    }
  }
  for (const std::string& note : gs.notes) std::fprintf(stderr, "[geometry]   %s\n", note.c_str());
}

void dumpFailedStep(const mesh::SheetMesh& mm, std::size_t geometricCount) {
  const std::string& dump = debugOptions().dump;
  if (dump.empty()) return;
  std::FILE* f = std::fopen(dump.c_str(), "w");
  if (f == nullptr) return;
  std::vector<int> uses(mm.vertexCount(), 0);
  for (const auto& t : mm.triangles)
    for (int k : t) ++uses[idx(k)];
  for (std::size_t i = 0; i < mm.vertexCount(); ++i)
    std::fprintf(f, "v %.9g %.9g %.9g\n# uses %d pattern %.9g %.9g sg %d\n", mm.positions[i].x(),
                 mm.positions[i].y(), mm.positions[i].z(), uses[i], mm.pattern[i].x(),
                 mm.pattern[i].y(), i < geometricCount ? 1 : 0);
  for (const auto& t : mm.triangles) std::fprintf(f, "f %d %d %d\n", t[0] + 1, t[1] + 1, t[2] + 1);
  std::fclose(f);
}

}  // namespace crumple::paper::detail
