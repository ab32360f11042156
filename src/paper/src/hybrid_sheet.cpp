#include "crumple/paper/hybrid_sheet.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <limits>
#include <optional>
#include <set>
#include <sstream>

#include "crumple/core/error.hpp"
#include "crumple/core/geometry2d.hpp"
#include "crumple/core/index.hpp"
#include "crumple/core/work_budget.hpp"
#include "crumple/paper/boundary_curve.hpp"
#include "crumple/paper/cone_fit.hpp"
#include "crumple/paper/damage.hpp"
#include "crumple/sim/colliders.hpp"
#include "hybrid_sheet_impl.hpp"
#include "region_tools.hpp"
#include "step_trace.hpp"

namespace crumple::paper {

namespace {

using detail::allFinite;
using detail::Clock;
using detail::msSince;

// Sums the stats of the animation steps of one frame.
void accumulate(HybridStepStats& total, const HybridStepStats& s) {
  total.elastic.newtonIterations += s.elastic.newtonIterations;
  total.elastic.halvings += s.elastic.halvings;
  total.elastic.solves += s.elastic.solves;
  total.elastic.finalStepNorm = s.elastic.finalStepNorm;
  total.elastic.newtonRetried += s.elastic.newtonRetried;
  total.elastic.selfContactDropped += s.elastic.selfContactDropped;
  total.elasticRetries += s.elasticRetries;
  total.elasticHeldStill += s.elasticHeldStill;
  total.undoneByBound += s.undoneByBound;
  GeometricStepStats& g = total.geometric;
  const GeometricStepStats& h = s.geometric;
  g.edgeFlips += h.edgeFlips;
  g.flatSplits += h.flatSplits;
  g.curvedCreated += h.curvedCreated;
  g.curvedBent += h.curvedBent;
  g.singularInserted += h.singularInserted;
  g.singularInCurved += h.singularInCurved;
  g.creases += h.creases;
  g.junctionMoves += h.junctionMoves;
  g.curvedFlattened += h.curvedFlattened;
  g.maxCompression = std::max(g.maxCompression, h.maxCompression);
  g.cuts.insert(g.cuts.end(), h.cuts.begin(), h.cuts.end());
  g.notes.insert(g.notes.end(), h.notes.begin(), h.notes.end());
  const int phaseOne = total.isometry.phaseOneIterations + s.isometry.phaseOneIterations;
  total.isometry = s.isometry;  // the frame ends with the last step's projection
  total.isometry.phaseOneIterations = phaseOne;
  total.ms.elastic += s.ms.elastic;
  total.ms.geometric += s.ms.geometric;
  total.ms.cones += s.ms.cones;
  total.ms.rebuild += s.ms.rebuild;
  total.ms.isometry += s.ms.isometry;
  total.ms.contacts += s.ms.contacts;
  total.ms.selfContacts += s.ms.selfContacts;
  total.ms.strainLimit += s.ms.strainLimit;
  {
    const StrainLimitStats before = total.strainLimit;
    total.strainLimit = s.strainLimit;
    total.strainLimit.iterations += before.iterations;
    if (before.lag > s.strainLimit.lag) {
      total.strainLimit.lag = before.lag;
      total.strainLimit.lagVertex = before.lagVertex;
    }
    mergeHandleLags(before.handleLags, total.strainLimit.handleLags);
    total.strainLimitRuns += s.strainLimit.ran ? 1 : 0;
    total.strainLimitCarried += s.strainLimit.carried ? 1 : 0;
  }
  total.elastic.contactMs += s.elastic.contactMs;
  total.elastic.selfContactMs += s.elastic.selfContactMs;
  total.elastic.airMs += s.elastic.airMs;
  total.elastic.selfContactSteps += s.elastic.selfContactSteps;
  total.coneSegments = s.coneSegments;
  total.topologyChanged = total.topologyChanged || s.topologyChanged;
}

}  // namespace

void HybridSheet::Impl::carryContacts(const std::vector<sim::ContactSample>& samples,
                                      const std::vector<Vec2>& patternBefore) {
  contacts.clear();
  const auto& pattern = sp.mesh.pattern;
  for (const sim::ContactSample& s : samples) {
    const Vec2& at = patternBefore[idx(s.vertex)];
    // The vertex at the same material point, else the nearest one.
    std::size_t best = 0;
    double bestDistance = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < pattern.size(); ++i) {
      const double d = (pattern[i] - at).squaredNorm();
      if (d < bestDistance) {
        bestDistance = d;
        best = i;
        if (d == 0.0) break;
      }
    }
    sim::ContactSample carried = s;
    carried.vertex = static_cast<int>(best);
    contacts.push_back(carried);
  }
  sim::mergeContactSamples(contacts);  // two samples may land on one vertex
}

HybridSheet::HybridSheet(GeometricMesh sg, const sim::Material& material,
                         const sim::SimParams& simParams, const CrumpleParams& params,
                         std::uint64_t seed)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.sg = std::move(sg);
  m.material = material;
  m.simParams = simParams;
  m.simParams.membraneScale = params.membraneScale;
  m.simParams.minVertexMassFraction = params.minVertexMassFraction;
  m.simParams.newtonTolerance = params.newtonTolerance;
  m.simParams.maxNewtonIterations = params.newtonIterations;
  m.params = params;
  m.seed = seed;
  for (const Vec2& a : m.sg.outline) {
    for (const Vec2& b : m.sg.outline) m.paperLength = std::max(m.paperLength, (a - b).norm());
  }
  const std::string problem = validate(m.sg);
  if (!problem.empty()) throw std::invalid_argument("HybridSheet: invalid S_G: " + problem);
  m.rebuildPhysical();
}

HybridSheet::~HybridSheet() = default;
HybridSheet::HybridSheet(HybridSheet&&) noexcept = default;
HybridSheet& HybridSheet::operator=(HybridSheet&&) noexcept = default;

void HybridSheet::setGrips(sim::GripFunction grips) { impl_->grips = std::move(grips); }

void HybridSheet::setRebuildCallback(
    std::function<void(const mesh::SheetMesh&, double t)> callback) {
  impl_->onRebuild = std::move(callback);
  if (impl_->onRebuild) impl_->onRebuild(impl_->sp.mesh, impl_->time);
}

void HybridSheet::setProjectionCallback(std::function<void(const ProjectionInput&)> callback) {
  impl_->onProjection = std::move(callback);
}

void HybridSheet::placeVertices(const std::vector<sim::Pin>& pins) {
  Impl& m = *impl_;
  for (const sim::Pin& p : pins) {
    if (inRange(m.sg.vertices, p.vertex)) {
      m.sg.vertices[idx(p.vertex)].position = p.position;
    }
  }
  updateSamples(m.sp, m.sg);
  for (const sim::Pin& p : pins) m.sp.mesh.positions[idx(p.vertex)] = p.position;
  m.elastic->setPositions(m.sp.mesh.positions);
}

void HybridSheet::setTime(double t) { impl_->time = t; }

void HybridSheet::setContacts(sim::ContactOptions options) {
  Impl& m = *impl_;
  m.elastic->setContacts(options);  // validates
  m.contact = std::move(options);
  m.contacts.clear();
}

const std::vector<sim::ContactSample>& HybridSheet::contacts() const { return impl_->contacts; }

void HybridSheet::saveState(StateWriter& w) const {
  const Impl& m = *impl_;
  w.tag("HYBR");
  w.f64(m.time);
  // S_G.
  w.count(m.sg.vertices.size());
  for (const auto& v : m.sg.vertices) {
    w.vec2(v.pattern);
    w.vec3(v.position);
    w.vec3(v.velocity);
    w.boolean(v.onBoundary);
    w.boolean(v.corner);
    w.boolean(v.singular);
    w.boolean(v.handle);
    w.i32(v.outlineSegment);
  }
  w.count(m.sg.faces.size());
  for (const auto& f : m.sg.faces) {
    for (int v : f.v) w.i32(v);
    w.i32(f.region);
  }
  w.count(m.sg.regions.size());
  for (const auto& r : m.sg.regions) {
    w.u8(static_cast<std::uint8_t>(r.type));
    w.i32(r.apex);
    w.count(r.rulings.size());
    for (const auto& ruling : r.rulings) {
      w.i32(ruling.a);
      w.i32(ruling.b);
    }
  }
  w.vec2s(m.sg.outline);
  // S_P.
  mesh::saveSheetMesh(w, m.sp.mesh);
  w.count(m.sp.samples.size());
  for (const auto& s : m.sp.samples) {
    w.i32(s.face);
    for (double x : s.weights) w.f64(x);
  }
  w.i32s(m.sp.faceOfTriangle);
  w.vec3s(m.spVelocities);
  sim::saveContactSamples(w, m.contacts);
  w.count(m.recentCuts.size());
  for (const auto& [p, left] : m.recentCuts) {
    w.vec2(p);
    w.i32(left);
  }
  m.elastic->saveState(w);
}

void HybridSheet::restoreState(StateReader& in) {
  Impl& m = *impl_;
  in.tag("HYBR");
  const double time = in.f64();
  GeometricMesh sg;
  sg.vertices.resize(in.count(61));
  for (auto& v : sg.vertices) {
    v.pattern = in.vec2();
    v.position = in.vec3();
    v.velocity = in.vec3();
    v.onBoundary = in.boolean();
    v.corner = in.boolean();
    v.singular = in.boolean();
    v.handle = in.boolean();
    v.outlineSegment = in.i32();
  }
  sg.faces.resize(in.count(20));
  for (auto& f : sg.faces) {
    for (int& v : f.v) v = in.i32();
    f.region = in.i32();
  }
  sg.regions.resize(in.count(13));
  for (auto& r : sg.regions) {
    const std::uint8_t type = in.u8();
    if (type > 1) in.fail("a region type of " + std::to_string(type));
    r.type = static_cast<mesh::RegionType>(type);
    r.apex = in.i32();
    r.rulings.resize(in.count(8));
    for (auto& ruling : r.rulings) {
      ruling.a = in.i32();
      ruling.b = in.i32();
    }
  }
  sg.outline = in.vec2s();
  const auto vertexOk = [&](int v) { return inRange(sg.vertices, v); };
  for (const auto& f : sg.faces) {
    for (int k = 0; k < f.size(); ++k)
      if (!vertexOk(f.v[idx(k)])) in.fail("a face's vertex is out of range");
    if (!inRange(sg.regions, f.region)) in.fail("a face's region is out of range");
  }
  for (const auto& r : sg.regions) {
    if (r.apex != -1 && !vertexOk(r.apex)) in.fail("a region's apex is out of range");
    for (const auto& ruling : r.rulings)
      if (!vertexOk(ruling.a) || !vertexOk(ruling.b)) in.fail("a ruling's vertex is out of range");
  }
  PhysicalMesh sp;
  sp.mesh = mesh::restoreSheetMesh(in);
  sp.samples.resize(in.count(36));
  for (auto& s : sp.samples) {
    s.face = in.i32();
    for (double& x : s.weights) x = in.f64();
  }
  sp.faceOfTriangle = in.i32s();
  std::vector<Vec3> velocities = in.vec3s();
  if (velocities.size() != sp.mesh.vertexCount())
    in.fail("the physical layer's velocities do not match its vertices");
  std::vector<sim::ContactSample> contacts = sim::restoreContactSamples(in, sp.mesh.vertexCount());
  std::vector<std::pair<Vec2, int>> recentCuts(in.count(20));
  for (auto& [p, left] : recentCuts) {
    p = in.vec2();
    left = in.i32();
  }
  m.sg = std::move(sg);
  m.sp = std::move(sp);
  m.spVelocities = std::move(velocities);
  m.contacts = std::move(contacts);
  m.recentCuts = std::move(recentCuts);
  m.time = time;
  m.isometry.reset();
  m.elastic.emplace(m.sp.mesh, m.material, m.simParams);
  m.elastic->setContacts(m.contact);
  m.elastic->restoreState(in);
}

// Thesis 3.3.3 "Remeshing" (Figs. 3.20-3.23).
std::optional<std::vector<GeometricCutResult>> HybridSheet::tear(
    const std::vector<TearAdvance>& advances, const GeometricCutOptions& options) {
  Impl& m = *impl_;
  GeometricMesh g = m.sg;
  const std::vector<Vec3>& x = m.elastic->positions();
  const std::vector<Vec3>& v = m.elastic->velocities();
  for (std::size_t i = 0; i < g.vertices.size(); ++i) {
    g.vertices[i].position = x[i];
    g.vertices[i].velocity = v[i];
  }
  // The cuts' new vertices on S_P as the elastic step left it (finer than
  // S_G's triangles).
  GeometricCutOptions onSurface = options;
  const mesh::SheetMesh& sp = m.sp.mesh;
  onSurface.surface = [&](const Vec2& p, Vec3& position, Vec3& velocity) {
    for (const auto& t : sp.triangles) {
      const Vec2& a = sp.pattern[idx(t[0])];
      const Vec2& b = sp.pattern[idx(t[1])];
      const Vec2& c = sp.pattern[idx(t[2])];
      const double area = cross2(b - a, c - a);
      const double wa = cross2(b - p, c - p) / area, wb = cross2(c - p, a - p) / area;
      const double wc = 1.0 - wa - wb;
      if (!(area > 0.0) || wa < -1e-9 || wb < -1e-9 || wc < -1e-9) continue;
      position = wa * x[idx(t[0])] + wb * x[idx(t[1])] + wc * x[idx(t[2])];
      velocity = wa * v[idx(t[0])] + wb * v[idx(t[1])] + wc * v[idx(t[2])];
      return true;
    }
    return false;
  };
  std::vector<GeometricCutResult> out;
  for (const TearAdvance& a : advances) {
    auto cut = cutGeometricMesh(g, a.from, a.to, onSurface, a.previousDirection);
    if (!cut) return std::nullopt;
    out.push_back(std::move(*cut));
  }
  const std::vector<Vec2> patternBefore = m.sp.mesh.pattern;
  const std::vector<sim::ContactSample> contactsBefore = m.contacts;
  m.sg = std::move(g);
  m.isometry.reset();
  m.rebuildPhysical();
  m.carryContacts(contactsBefore, patternBefore);
  return out;
}

const sim::ElasticSheet& HybridSheet::elastic() const { return *impl_->elastic; }
const GeometricMesh& HybridSheet::geometric() const { return impl_->sg; }
const PhysicalMesh& HybridSheet::physical() const { return impl_->sp; }
const CrumpleParams& HybridSheet::params() const { return impl_->params; }

int HybridSheet::singularVertexCount() const {
  return static_cast<int>(std::count_if(impl_->sg.vertices.begin(), impl_->sg.vertices.end(),
                                        [](const GeometricVertex& v) { return v.singular; }));
}

int HybridSheet::interiorSingularVertexCount() const {
  return static_cast<int>(
      std::count_if(impl_->sg.vertices.begin(), impl_->sg.vertices.end(),
                    [](const GeometricVertex& v) { return v.singular && !v.onBoundary; }));
}

// paper Fig. 16 (a)-(b): the elastic step of S_P from t over dt with the handles as hard
// constraints, retried once with every pin on its target.
void HybridSheet::Impl::elasticStep(double t, double dt, const sim::PinFunction& pins,
                                    const sim::PinFunction& nodePins, HybridStepStats& stats) {
  Impl& m = *this;
  const std::vector<Vec3> elasticStart =
      m.crossingGuard() > 0.0 ? m.elastic->positions() : std::vector<Vec3>{};
  m.elastic->setGrips(m.laggingGrips(pins, nodePins));
  try {
    stats.elastic = m.elastic->advance(t, dt, pins);
  } catch (const WorkBudgetExceeded&) {
    throw;  // the shot's cost guard: no retry
  } catch (const NumericalError&) {
    // The isometry leaves the tangent-plane pins where the lengths put them
    // (isometryHoldsTangentPins); when the elastic step cannot pull them back
    // from there, it is retried once with every pin on its target.
    std::vector<sim::Pin> now;
    pins(t, now);
    std::vector<Vec3> x = m.elastic->positions();
    for (const sim::Pin& p : now) x[idx(p.vertex)] = p.position;
    m.elastic->setPositions(x);
    stats.elastic = m.elastic->advance(t, dt, pins);
    ++stats.elasticRetries;
  }
  if (!elasticStart.empty()) {
    // Held: a handle pins S_P, or a finger grips it, somewhere in the step.
    std::vector<sim::Pin> held;
    std::vector<sim::Grip> gripped;
    pins(t + dt, held);
    if (m.grips) m.grips(t + dt, gripped);
    const bool isHeld = !held.empty() || !gripped.empty();
    if (!(m.keepElasticStepOutOfItself(elasticStart, dt, isHeld) > 0.0) &&
        m.elastic->positions() == elasticStart)
      ++stats.elasticHeldStill;
  }
}

// paper Fig. 16 (d)-(e), thesis Algorithm 1: the geometric step of S_G (junctions, edge flips,
// folded and split flat regions, compression treatment) with S_P at x after the elastic step.
void HybridSheet::Impl::geometricStep(const BoundaryCurve& curve, const std::vector<Vec3>& x,
                                      int frame, const CrumpleParams& stepParams,
                                      std::uint64_t& draw, HybridStepStats& stats) {
  Impl& m = *this;
  const BoundaryPosition boundary = [&curve](double s) { return curve.evaluate(s); };
  // With invariant checks on, every sub-step is checked so a failure names it.
  const auto checkAfter = [&](const char* step) {
    if (!m.params.checkInvariants) return;
    if (const std::string problem = validate(m.sg); !problem.empty()) {
      throw NumericalError("geometric", frame,
                           std::string("S_G invariant broken after ") + step + ": " + problem);
    }
  };
  updateJunctions(m.sg, m.params, boundary, stats.geometric);
  checkAfter("junction update");
  stats.geometric.edgeFlips = flipCompressedEdges(m.sg, m.params);
  checkAfter("edge flips");
  mesh::SheetMesh bentSp = m.sp.mesh;  // S_P as the elastic step left it
  bentSp.positions = x;
  bendFoldedFlatRegions(m.sg, m.params, boundary, stats.geometric, &bentSp);
  checkAfter("folded flat regions");
  stats.geometric.flatSplits = splitFlatRegions(m.sg, m.params);
  checkAfter("flat-region splits");
  const CounterRng rng(m.seed, frame, RngPurpose::SingularityPlacement);
  // Regions cut in the last remeshCooldown steps wait (the cooldown).
  const FaceFilter settled = [&m](int face) { return !m.holdsRecentCut(m.sg.faces[idx(face)]); };
  treatCompression(m.sg, stepParams, boundary, rng, draw, stats.geometric, settled);
  checkAfter("compression treatment");
  treatCurvedCompression(m.sg, stepParams, rng, draw, stats.geometric, settled);
  checkAfter("curved-region compression");
}

// paper Fig. 16 (f), Sec. 6.2: every curved region without an apex refitted as generalized
// cones, each fit undone when it breaks S_G or compresses a ruling.
void HybridSheet::Impl::refitCones(const BoundaryCurve& curve, HybridStepStats& stats) {
  Impl& m = *this;
  for (std::size_t r = 0; r < m.sg.regions.size(); ++r) {
    const Region& region = m.sg.regions[r];
    if (region.type != mesh::RegionType::Curved || region.apex >= 0 || region.rulings.size() < 3)
      continue;
    const GeometricMesh before = m.sg;
    const ConeRefitResult fit =
        refitCurvedRegion(m.sg, static_cast<int>(r), curve, m.params, m.paperLength);
    GeometricMesh compacted = m.sg;  // the fit leaves unused vertices for compact()
    compact(compacted);
    if (const std::string problem = validate(compacted); !problem.empty()) {
      m.sg = before;  // transactional, like the other remeshing steps
      stats.geometric.notes.push_back("cone fit of curved region " + std::to_string(r) +
                                      " undone (" + problem + ")");
      continue;
    }
    // A ruling is a straight segment of the surface, as long in space as in
    // the pattern. A fit whose new rulings are shorter than their pattern
    // (cutting across S_P's bending) by more than a d-cone's threshold, and
    // more than the rulings it replaces, is not a cone of this surface:
    // undone (docs/CRUMPLING.md).
    if (fit.changed) {
      const double after = worstRulingCompression(m.sg, static_cast<int>(r));
      if (after > m.params.curvedCompressionFactor * m.params.epsC &&
          after > worstRulingCompression(before, static_cast<int>(r))) {
        m.sg = before;
        stats.geometric.notes.push_back("cone fit of curved region " + std::to_string(r) +
                                        " undone (a new ruling compressed " +
                                        std::to_string(after) + ")");
        continue;
      }
    }
    stats.coneSegments += fit.segmentCount;
  }
  compact(m.sg);
  // Faces created by the remeshing are flat only when coplanar: regions are
  // the maximal coplanar sets again before S_P is built.
  splitFlatRegions(m.sg, m.params);
}

// paper Fig. 16 (h), Sec. 6.3: S_P's positions after the isometry projection with the handles
// fixed (`pinned` at t), kept unprojected when it would pass S_P through itself or lengthen.
std::vector<Vec3> HybridSheet::Impl::projectIsometry(double t, const std::vector<sim::Pin>& pinned,
                                                     int frame, HybridStepStats& stats) {
  Impl& m = *this;
  std::vector<int> fixed;
  for (const sim::Pin& p : pinned) {
    // Tangent-plane pins are S_P vertices that are not handles: they bind in
    // the elastic step only unless isometryHoldsTangentPins (params.hpp).
    if (!m.params.isometryHoldsTangentPins && !m.isHandle(p.vertex)) continue;
    fixed.push_back(p.vertex);
  }
  std::sort(fixed.begin(), fixed.end());
  fixed.erase(std::unique(fixed.begin(), fixed.end()), fixed.end());
  if (!m.isometry || !m.isometry->sameTopology(m.sp.mesh.triangles, fixed) ||
      idx(m.isometry->vertexCount()) != m.sp.mesh.vertexCount() || stats.topologyChanged) {
    m.isometry.emplace(m.sp.mesh.pattern, m.sp.mesh.triangles, fixed, m.isometryOptions());
  }
  if (m.onProjection) {
    std::vector<int> all;
    for (const sim::Pin& p : pinned) all.push_back(p.vertex);
    std::sort(all.begin(), all.end());
    all.erase(std::unique(all.begin(), all.end()), all.end());
    m.onProjection({m.sp.mesh.pattern, m.sp.mesh.triangles, fixed, all, m.sp.mesh.positions,
                    m.isometryOptions(), m.params.isometryIterations, frame, t});
  }
  std::vector<Vec3> positions = m.sp.mesh.positions;
  stats.isometry = m.isometry->project(positions, m.params.isometryIterations);
  if (!allFinite(positions)) throw NumericalError("isometry", frame, "non-finite positions");
  if (m.passesThroughItself(m.sp.mesh.positions, positions)) {
    // Nor let it move the sheet through itself: it knows no contacts (cut
    // back to where it would, rather than dropped, it leaves S_P compressed:
    // docs/CRUMPLING.md "Self-contact in the crumpling samples").
    positions = m.sp.mesh.positions;
    stats.isometry.meanLengthErrorAfter = stats.isometry.meanLengthErrorBefore;
    stats.isometry.meanDisplacement = 0.0;
  }
  if (stats.isometry.meanLengthErrorAfter > stats.isometry.meanLengthErrorBefore) {
    // Never let the projection make lengths worse (it has no convergence
    // guarantee, paper Sec. 6.3): keep the unprojected S_P then.
    positions = m.sp.mesh.positions;
    stats.isometry.meanLengthErrorAfter = stats.isometry.meanLengthErrorBefore;
    stats.isometry.meanDisplacement = 0.0;
  }
  return positions;
}

// paper Fig. 16 (g) precondition: S_G after the geometric step and the cone fit has finite
// positions and (checkInvariants) holds its invariants.
void HybridSheet::Impl::checkGeometric(int frame) const {
  const Impl& m = *this;
  for (const GeometricVertex& gv : m.sg.vertices) {
    if (!gv.position.allFinite())
      throw NumericalError("geometric", frame, "S_G vertex position is not finite");
  }
  if (m.params.checkInvariants) {
    const std::string problem = validate(m.sg, m.params.theta0);
    if (!problem.empty())
      throw NumericalError("geometric", frame, "S_G invariant broken: " + problem);
  }
}

// paper Fig. 16 (h) end: S_P and S_G take the step's final positions; the cooldown of the
// recent cuts advances and this step's cuts start theirs.
void HybridSheet::Impl::commitPositions(const std::vector<Vec3>& positions,
                                        const HybridStepStats& stats) {
  Impl& m = *this;
  m.sp.mesh.positions = positions;
  for (std::size_t i = 0; i < m.sg.vertices.size(); ++i) m.sg.vertices[i].position = positions[i];
  m.elastic->setPositions(positions);
  m.noteHinge(2);
  for (auto& cut : m.recentCuts) --cut.second;
  std::erase_if(m.recentCuts, [](const auto& cut) { return cut.second <= 0; });
  for (const Vec2& p : stats.geometric.cuts) m.recentCuts.emplace_back(p, m.params.remeshCooldown);
}

// One animation step of the paper (Fig. 16, thesis Algorithm 1) from t to
// t + dt: an elastic step of S_P, S_P -> S_G, the geometric step, cone
// fitting, S_P rebuilt from S_G, the isometry projection and (with
// maxEdgeStrain) the strain limit. `stage` names
// the stage running, for the error message when it throws.
void HybridSheet::Impl::animationStep(double t, double dt, const sim::PinFunction& nodePins,
                                      int frame, int singularBudget, std::uint64_t& draw,
                                      HybridStepStats& stats, const char*& stage) {
  Impl& m = *this;
  // The handles on their nodes, a lagging one on its way back (catchUpPins).
  const sim::PinFunction pins = m.catchUpPins(t, dt, nodePins);
  // The step's start, for the strain limit's carried start and for undoing
  // a structure change it cannot bound.
  const mesh::SheetMesh spBefore = m.params.maxEdgeStrain > 0.0 ? m.sp.mesh : mesh::SheetMesh{};
  const GeometricMesh sgBefore = m.params.maxEdgeStrain > 0.0 ? m.sg : GeometricMesh{};
  CrumpleParams stepParams = m.params;
  stepParams.maxSingularPerFrame = singularBudget;
  // (a)-(b) elastic relaxation of S_P with the handles as hard constraints.
  stage = "elastic";
  auto t0 = Clock::now();
  m.elasticStep(t, dt, pins, nodePins, stats);
  stats.ms.elastic = msSince(t0);
  m.noteHinge(0);
  const std::vector<sim::ContactSample> elasticContacts = m.elastic->contacts();
  const std::vector<Vec2> elasticPattern = m.sp.mesh.pattern;
  const std::vector<Vec3>& x = m.elastic->positions();
  const std::vector<Vec3>& v = m.elastic->velocities();
  // The elastic step's S_P, for undoing a geometric step that stretches it.
  const std::vector<Vec3> elasticX = m.params.maxEdgeStrain > 0.0 ? x : std::vector<Vec3>{};
  const std::vector<Vec3> elasticV = m.params.maxEdgeStrain > 0.0 ? v : std::vector<Vec3>{};
  if (m.traceLevel > 0)
    m.traceElasticStrain = LengthProjector(m.sp.mesh.pattern, m.sp.mesh.triangles).strain(x).first;
  // (c) S_P -> S_G.
  for (std::size_t i = 0; i < m.sg.vertices.size(); ++i) {
    m.sg.vertices[i].position = x[i];
    m.sg.vertices[i].velocity = v[i];
  }
  // (d)-(e) geometric step (thesis Algorithm 1).
  stage = "geometric";
  t0 = Clock::now();
  const BoundaryCurve curve =
      boundaryCurveFromMesh(m.sg, m.sp.mesh.pattern, x, 1e-9 * m.paperLength);
  m.geometricStep(curve, x, frame, stepParams, draw, stats);
  stats.ms.geometric = msSince(t0);
  // (f) generalized cones (paper Sec. 6.2).
  stage = "cones";
  t0 = Clock::now();
  m.refitCones(curve, stats);
  stats.ms.cones = msSince(t0);
  m.checkGeometric(frame);
  m.time = t + dt;
  // (g) S_P from S_G.
  stage = "rebuild";
  t0 = Clock::now();
  stats.topologyChanged = m.rebuildPhysical();
  m.noteHinge(1);
  stats.ms.rebuild = msSince(t0);
  if (m.params.checkInvariants) m.checkInvariants(frame, "geometric");
  // (h) isometry with the handles fixed (paper Sec. 6.3).
  stage = "isometry";
  t0 = Clock::now();
  std::vector<sim::Pin> pinned;
  pins(t + dt, pinned);
  std::vector<Vec3> positions = m.projectIsometry(t + dt, pinned, frame, stats);
  stats.ms.isometry = msSince(t0);
  if (m.params.maxEdgeStrain > 0.0) {
    stage = "strain limit";
    t0 = Clock::now();
    const double contactsBefore = stats.ms.contacts + stats.ms.selfContacts;
    m.undoStretchingGeometry(spBefore, sgBefore, elasticX, elasticV, positions, stats);
    m.limitStepStrain(spBefore, sgBefore, pinned, frame, positions, stats);
    std::vector<sim::Pin> nodes;
    nodePins(t + dt, nodes);
    m.measureLags(nodes, positions, stats.strainLimit);
    // The contact rounds inside it count as contacts.
    stats.ms.strainLimit =
        msSince(t0) - (stats.ms.contacts + stats.ms.selfContacts - contactsBefore);
  }
  if (m.contactsOn()) {
    stage = "contacts";
    // With the strain limit on, the failsafe ran inside it as its
    // constraints, last before its final projection: where they still
    // conflict the bound wins (docs/CRUMPLING.md "The geometric step under
    // the bound").
    if (m.params.maxEdgeStrain <= 0.0)
      sim::projectOutOfContacts(m.contact, m.sp.mesh.triangles, m.sp.mesh.pattern, m.heldBy(pinned),
                                positions, &stats.ms.contacts, &stats.ms.selfContacts);
    const auto carryStart = Clock::now();
    m.carryContacts(elasticContacts, elasticPattern);
    stats.ms.contacts += msSince(carryStart);
    stage = "isometry";
  }
  t0 = Clock::now();
  m.commitPositions(positions, stats);
  stats.ms.isometry += msSince(t0);
  if (m.traceLevel > 0) {
    std::vector<sim::Pin> pinned;
    pins(t + dt, pinned);
    detail::printStepTrace(m.traceLevel, frame, m.sg, m.sp, *m.elastic, stats, pinned, m.traceHinge,
                           m.traceElasticStrain);
  }
}

HybridStepStats HybridSheet::advance(double t, double dt, int substeps,
                                     const sim::PinFunction& pins, int frame) {
  Impl& m = *impl_;
  HybridStepStats stats;
  // The state before the step, restored when a stage fails.
  const GeometricMesh sgBefore = m.sg;
  const std::vector<Vec3> xBefore = m.elastic->positions();
  const std::vector<Vec3> vBefore = m.elastic->velocities();
  const char* stage = "elastic";
  try {
    // The frame's substeps are the paper's animation steps; singular
    // vertices appear at most maxSingularPerFrame per frame.
    const int n = std::max(1, substeps);
    std::uint64_t draw = 0;
    for (int k = 0; k < n; ++k) {
      HybridStepStats s;
      const int budget = m.params.maxSingularPerFrame - stats.geometric.singularInserted;
      m.animationStep(t + dt * k / n, dt / n, pins, frame, std::max(0, budget), draw, s, stage);
      accumulate(stats, s);
    }
  } catch (const std::exception& e) {
    detail::dumpFailedStep(m.sp.mesh, m.sg.vertices.size());
    m.sg = sgBefore;
    m.time = t;
    m.elastic.reset();
    m.isometry.reset();
    m.rebuildPhysical();
    m.elastic->setPositions(xBefore);
    m.elastic->setVelocities(vBefore);
    m.sp.mesh.positions = xBefore;
    m.spVelocities = vBefore;
    if (const auto* numerical = dynamic_cast<const NumericalError*>(&e)) {
      if (numerical->frame() >= 0) throw;
      throw NumericalError(numerical->stage(), frame, numerical->problem());
    }
    throw NumericalError(stage, frame, e.what());
  }
  return stats;
}

}  // namespace crumple::paper
