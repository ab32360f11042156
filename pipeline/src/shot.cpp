#include "crumple/pipeline/shot.hpp"

#include <unistd.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <string_view>

#include "checkpoint.hpp"
#include "cost_guard.hpp"
#include "crumple/core/error.hpp"
#include "crumple/core/progress.hpp"
#include "crumple/core/work_budget.hpp"
#include "crumple/exporters/pcache_contacts.hpp"
#include "crumple/exporters/pcache_sound.hpp"
#include "crumple/exporters/pcache_structure.hpp"
#include "crumple/exporters/pcache_tear.hpp"
#include "crumple/exporters/png.hpp"
#include "crumple/paper/hybrid_sheet.hpp"
#include "crumple/paper/initial_sheet.hpp"
#include "crumple/pipeline/contacts.hpp"
#include "crumple/pipeline/handle_rig.hpp"
#include "crumple/pipeline/inspect.hpp"
#include "crumple/pipeline/output_lock.hpp"
#include "crumple/pipeline/sound.hpp"
#include "crumple/render/osmesa_renderer.hpp"
#include "crumple/sim/colliders.hpp"
#include "crumple/sim/elastic_sheet.hpp"
#include "crumple/sound/events.hpp"
#include "crumple/tear/tear_atlas.hpp"
#include "frame_output.hpp"
#include "json_writer.hpp"

namespace crumple::pipeline {
namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// Animation time of a frame: f / fps, the DCC convention (docs/SCENE.md "Time").
double frameTime(const io::SceneSpec& scene, int frame) { return scene.frameTime(frame); }

// Creates the folder and checks that a file can be written in it.
void prepareOutputDir(const std::string& dir, const std::string& what) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw InputError(dir, "cannot create the " + what + " folder: " + ec.message());
  const fs::path probe = fs::path(dir) / ".crumple-write-probe";
  {
    std::ofstream out(probe);
    if (!out) throw InputError(dir, "the " + what + " folder is not writable");
  }
  fs::remove(probe, ec);
}

sim::Material materialOf(const io::PaperPreset& paper) {
  sim::Material m;
  m.name = paper.name;
  m.thickness = paper.thickness;
  m.density = paper.density;
  m.youngsModulus = paper.youngsModulus;
  m.poissonRatio = paper.poissonRatio;
  return m;
}

cache::CameraRecord cameraAt(const io::SceneSpec& scene, const io::AnimationScene* animation,
                             double t) {
  cache::CameraRecord rec;
  if (!scene.camera.node.empty() && animation != nullptr) {
    const auto cam = animation->camera(scene.camera.node, t);
    if (!cam)
      throw InputError(scene.file, "[camera] node '" + scene.camera.node + "' has no camera in " +
                                       animation->file());
    rec.position = cam->position;
    rec.rotation = cam->rotation;
    rec.yfov = cam->yfov > 0.0 && !scene.camera.fovExplicit ? cam->yfov : scene.camera.yfov;
    return rec;
  }
  const auto c = render::Camera::lookAt(scene.camera.position, scene.camera.lookAt, scene.camera.up,
                                        scene.camera.yfov, scene.camera.width, scene.camera.height);
  rec.position = c.position;
  rec.rotation = c.rotation;
  rec.yfov = c.yfov;
  return rec;
}

// After the frames: the contact sheet (DIR/contact_sheet.png) and the movie
// (DIR/preview.mp4, with DIR/sound.wav when there is one), DIR being the
// shot's folder.
void finishFrames(const std::string& framesDir, const FrameRange& range, double fps,
                  const std::string& shotDir, const RenderSettings& settings,
                  std::string& contactSheetPath, std::string& moviePath,
                  std::vector<std::string>& notes) {
  const fs::path dir = shotDir.empty() ? fs::path(".") : fs::path(shotDir);
  if (settings.contactSheet) {
    contactSheetPath = (dir / "contact_sheet.png").string();
    (void)detail::writeContactSheet(framesDir, range.first, range.last, contactSheetPath);
  }
  if (settings.movie) {
    std::string note;
    const std::string movie = (dir / "preview.mp4").string();
    if (detail::makeMovie(framesDir, range.first, range.last, fps, (dir / "sound.wav").string(),
                          movie, note))
      moviePath = movie;
    if (!note.empty()) notes.push_back(note);
  }
}

// Above this mean edge-length error (c_mean) a hybrid shot warns: the
// model's target is 0.5 % (issue 3; paper Table IV reaches 0.17-1.47 %).
constexpr double kLengthErrorWarning = 0.01;
// A handle further than this from its node lags (strain_limit.hpp).
constexpr double kLagReported = 1e-6;

// Adds one frame's lag of each handle (strain limit: (vertex, lag)) to the
// per-handle record, one entry per handle of the rig in its order.
void noteHandleLags(const HandleRig& rig, const std::vector<std::pair<int, double>>& lags,
                    int frame, std::vector<ShotReport::HandleLag>& record) {
  const auto& handles = rig.handles();
  if (record.size() != handles.size()) {
    record.assign(handles.size(), {});
    for (std::size_t h = 0; h < handles.size(); ++h) record[h].name = handles[h].name;
  }
  for (std::size_t h = 0; h < handles.size(); ++h)
    for (const auto& [vertex, lag] : lags) {
      if (vertex != handles[h].vertex || lag <= kLagReported) continue;
      ShotReport::HandleLag& r = record[h];
      if (r.frames++ == 0) r.firstFrame = frame;
      if (lag > r.max) {
        r.max = lag;
        r.maxFrame = frame;
      }
    }
}

paper::CrumpleParams crumpleParamsOf(const io::HybridSpec& h) {
  paper::CrumpleParams p;
  p.rhoBound = h.rhoBound;
  p.rhoInt = h.rhoInt;
  p.theta0 = h.theta0;
  p.thetaLow = h.thetaLow;
  p.thetaHigh = h.thetaHigh;
  p.epsBlaschke = h.epsBlaschke;
  p.epsC = h.epsC;
  p.sigma = h.sigma;
  p.thetaRest = h.thetaRest;
  p.damage = h.damage;
  p.isometryIterations = h.isometryIterations;
  p.isometryLengthSweeps = h.isometryLengthSweeps;
  p.isometryLengthTolerance = h.isometryLengthTolerance;
  p.maxSingularPerFrame = h.maxSingularPerFrame;
  p.remeshCooldown = h.remeshCooldown;
  p.maxEdgeStrain = h.maxEdgeStrain;
  p.lagCatchUpSpeed = h.lagCatchUpSpeed;
  // Region invariants after every geometric step: always in debug builds,
  // on request (CRUMPLE_CHECK_INVARIANTS=1) in release builds.
  if (const char* env = std::getenv("CRUMPLE_CHECK_INVARIANTS"); env != nullptr && env[0] == '1')
    p.checkInvariants = true;
  return p;
}

// The hybrid model's starting S_G: the rectangle with a vertex at every
// handle's pattern point (or the sheet point under its node at the first
// frame), so handles hold exactly the point they name.
paper::InitialSheet hybridStartSheet(const io::SceneSpec& scene,
                                     const io::AnimationScene* animation, double t0) {
  const auto& s = scene.sheet;
  if (s.kind != io::SheetSpec::Kind::Rectangle)
    throw InputError(scene.file,
                     "[model] type = \"hybrid\" needs a rectangular [sheet] (width, height); "
                     "pattern_mesh sheets run with the elastic model only");
  const Vec3 u = s.uAxis.normalized();
  const Vec3 v = s.vAxis.normalized();
  std::vector<Vec2> points;
  for (const auto& h : scene.handles) {
    if (h.patternPoint) {
      points.push_back(*h.patternPoint);
    } else if (animation != nullptr && animation->hasNode(h.node)) {
      const Vec3 x = animation->worldPose(h.node, t0).position - s.origin;
      points.push_back(
          Vec2(std::clamp(x.dot(u), 0.0, s.width), std::clamp(x.dot(v), 0.0, s.height)));
    }
  }
  return paper::makeFlatSheet(s.width, s.height, points, s.origin, u, v);
}

sound::EventParams eventParamsOf(const io::SoundSpec& s) {
  sound::EventParams p;
  p.gridSpacing = s.gridSpacing;
  p.curvatureThreshold = s.curvatureThreshold;
  p.maxDihedral = s.maxDihedral;
  p.freeBorderRadius = s.freeBorderRadius;
  p.minSlideSpeed = s.minSlideSpeed;
  return p;
}

tear::TearingParams tearingParamsOf(const io::TearSpec& t) {
  tear::TearingParams p;
  p.griffith.resistance = t.resistance;
  p.griffith.tipDamage = t.tipDamage;
  p.griffith.speed = t.speed;
  p.griffith.minInwardAngle = t.minInwardAngle;
  p.fibers.texelSize = t.texel;
  p.fibers.featureSize = t.fiberSize;
  p.fibers.octaves = t.fiberOctaves;
  p.fibers.anisotropy = t.fiberAnisotropy;
  p.fibers.fiberDirection = t.fiberDirection;
  p.detail.blend = t.detailBlend;
  p.detail.stressWidth = t.stressWidth;
  p.maxNewTearsPerFrame = t.maxNewPerFrame;
  p.branchAngle = t.epsA;
  return p;
}

// A torn crumpling-model sheet handed over to the elastic model settles in
// these tiny steps (s) before it moves on.
constexpr int kRelaxSteps = 4;
// The crumpling model's tears are slits of this width in S_G's pattern
// (paper::GeometricCutOptions::kerf); their lips are within a few kerfs of
// the tear's cut (the copies of a tip where it turned, a tear's first
// copies on the outline).
constexpr double kTearKerf = 1e-5;
constexpr double kLipTolerance = 12.0 * kTearKerf;
// The crumpling model's tears start at least this far (rad) from the
// outline's direction (tear::TearingParams::minStartAngle): cylinder-fold
// with [tear] started one at 17 degrees along its bottom edge, 0.66 mm in,
// and S_P's sliver triangles there failed the elastic step four frames on.
constexpr double kMinStartAngle = 25.0 * std::numbers::pi / 180.0;
constexpr double kRelaxDt = 1e-4;

// The tearing parameters of the model the sheet runs.
tear::TearingParams tearingParamsFor(const io::SceneSpec& scene, bool crumplingModel) {
  tear::TearingParams p = tearingParamsOf(scene.tear);
  // The crumpling model's cuts are S_G's (paper::cutGeometricMesh), S_P
  // only finds where they go: over S_P's long curved-region cells the
  // elastic model's snap would pull short advances back onto the tip.
  if (crumplingModel) {
    p.snap = paper::GeometricCutOptions{}.snap;
    p.minStartAngle = kMinStartAngle;
    p.maxTurn = paper::GeometricCutOptions{}.maxTurn;
  }
  return p;
}

// The crumpling model's sheet at the elastic model's resolution (a torn
// sheet handed over, docs/TEARING.md): the scene's rectangle mesh, the
// vertex nearest each handle's point moved onto it, every vertex placed and
// given a velocity by interpolating S_P (positions x, velocities v) in the
// pattern.
struct ResampledSheet {
  mesh::SheetMesh mesh;
  std::vector<Vec3> velocities;
  std::vector<int> handleVertices;
};
ResampledSheet resampleSheet(const mesh::SheetMesh& fine, const mesh::SheetMesh& sp,
                             const std::vector<Vec3>& x, const std::vector<Vec3>& v,
                             const std::vector<int>& spHandles) {
  ResampledSheet out;
  out.mesh = fine;
  for (int h : spHandles) {
    const Vec2 p = sp.pattern[static_cast<std::size_t>(h)];
    const int n = mesh::nearestPatternVertex(out.mesh, p);
    if (std::find(out.handleVertices.begin(), out.handleVertices.end(), n) !=
        out.handleVertices.end())
      throw std::invalid_argument(
          "two handles fall on one vertex of the elastic mesh (a finer [sheet] max_edge "
          "separates them)");
    out.mesh.pattern[static_cast<std::size_t>(n)] = p;
    out.handleVertices.push_back(n);
  }
  const auto cross = [](const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); };
  out.velocities.resize(out.mesh.vertexCount());
  for (std::size_t i = 0; i < out.mesh.vertexCount(); ++i) {
    const Vec2 q = out.mesh.pattern[i];
    double bestMin = -std::numeric_limits<double>::infinity();
    Vec3 bx = Vec3::Zero(), bv = Vec3::Zero();
    for (const auto& t : sp.triangles) {
      const Vec2 a = sp.pattern[static_cast<std::size_t>(t[0])];
      const Vec2 b = sp.pattern[static_cast<std::size_t>(t[1])];
      const Vec2 c = sp.pattern[static_cast<std::size_t>(t[2])];
      const double area = cross(b - a, c - a);
      if (!(std::abs(area) > 1e-14)) continue;  // a sliver cannot place anything
      const double wb = cross(q - a, c - a) / area, wc = cross(b - a, q - a) / area;
      const double wa = 1.0 - wb - wc;
      const double least = std::min({wa, wb, wc});
      if (!(least > bestMin)) continue;
      bestMin = least;
      bx = wa * x[static_cast<std::size_t>(t[0])] + wb * x[static_cast<std::size_t>(t[1])] +
           wc * x[static_cast<std::size_t>(t[2])];
      bv = wa * v[static_cast<std::size_t>(t[0])] + wb * v[static_cast<std::size_t>(t[1])] +
           wc * v[static_cast<std::size_t>(t[2])];
    }
    out.mesh.positions[i] = bx;
    out.velocities[i] = bv;
  }
  return out;
}

void validateRange(const io::SceneSpec& scene, const FrameRange& range) {
  if (range.first < scene.frameStart || range.last > scene.frameEnd)
    throw InputError(
        scene.file, "--frames " + std::to_string(range.first) + "-" + std::to_string(range.last) +
                        " is outside the scene's frames " + std::to_string(scene.frameStart) + "-" +
                        std::to_string(scene.frameEnd));
}

void writeTextAtomically(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  bool written = false;
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << text;
    out.close();
    written = static_cast<bool>(out);
  }
  std::error_code ec;
  if (written) fs::rename(tmp, path, ec);
  if (!written || ec) {
    fs::remove(tmp, ec);  // a full disk leaves no temporary behind
    throw InputError(path, "cannot write");
  }
}

}  // namespace

// The STRC block's counts from a frame's animation steps.
cache::StructureChanges structureChangesOf(const paper::HybridStepStats& s) {
  const auto count = [](int n) { return static_cast<std::uint32_t>(std::max(0, n)); };
  const paper::GeometricStepStats& g = s.geometric;
  cache::StructureChanges c;
  c.singularFromFlat = count(g.singularInserted - g.singularInCurved);
  c.singularFromRuling = count(g.singularInCurved);
  c.curvedFromCompression = count(g.curvedCreated - g.curvedBent);
  c.curvedFromFolding = count(g.curvedBent);
  c.creases = count(g.creases);
  c.flatSplits = count(g.flatSplits);
  c.curvedFlattened = count(g.curvedFlattened);
  c.undoneByStretch = count(s.undoneByBound);
  return c;
}

const char* tearKindName(tear::CandidateKind kind) {
  switch (kind) {
    case tear::CandidateKind::Tip:
      return "tip";
    case tear::CandidateKind::Junction:
      return "junction";
    case tear::CandidateKind::HandleBorder:
      return "handle_border";
    case tear::CandidateKind::InwardCorner:
      return "inward_corner";
  }
  return "?";
}

FrameRange parseFrameRange(const std::string& text) {
  // "A-B" or "A", A and B integers (A may be negative: "-5--2" is -5 to -2).
  const auto bad = [&] { return InputError("--frames", "expected A-B or A, got '" + text + "'"); };
  const auto parseInt = [&](std::string_view s) {
    int value = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
    if (s.empty() || ec != std::errc() || end != s.data() + s.size()) throw bad();
    return value;
  };
  const std::string_view all(text);
  const auto dash = all.find('-', 1);  // a leading '-' is a sign
  FrameRange r;
  r.first = parseInt(all.substr(0, dash));
  r.last = dash == std::string_view::npos ? r.first : parseInt(all.substr(dash + 1));
  if (r.last < r.first) throw InputError("--frames", "range " + text + " ends before it starts");
  return r;
}

mesh::SheetMesh buildSheet(const io::SceneSpec& scene, const io::AnimationScene* animation) {
  const auto& s = scene.sheet;
  if (s.kind == io::SheetSpec::Kind::Rectangle || s.kind == io::SheetSpec::Kind::Outline) {
    const double maxEdge = s.maxEdge > 0.0 ? s.maxEdge : std::min(s.width, s.height) / 16.0;
    auto sheet = s.kind == io::SheetSpec::Kind::Rectangle
                     ? mesh::makeRectangleSheet(s.width, s.height, maxEdge)
                     : mesh::makePolygonSheet(s.outline, maxEdge);
    mesh::placePattern(sheet, s.origin, s.uAxis.normalized(), s.vAxis.normalized());
    return sheet;
  }
  // A flat pattern mesh from the animation file: its plane gives the pattern.
  if (animation == nullptr)
    throw InputError(scene.file, "[sheet] pattern_mesh needs an animation file");
  const auto imported = animation->mesh(s.patternMesh);
  if (!imported || imported->triangles.empty())
    throw InputError(scene.file, "[sheet] pattern_mesh '" + s.patternMesh +
                                     "' is not a mesh node of " + animation->file());
  Vec3 centre = Vec3::Zero();
  for (const auto& v : imported->vertices) centre += v;
  centre /= static_cast<double>(imported->vertices.size());
  Mat3 cov = Mat3::Zero();
  for (const auto& v : imported->vertices) cov += (v - centre) * (v - centre).transpose();
  Eigen::SelfAdjointEigenSolver<Mat3> eig(cov);
  const Vec3 normal = eig.eigenvectors().col(0);
  Vec3 u = eig.eigenvectors().col(2);
  Vec3 v = normal.cross(u);
  double extent = 0.0, deviation = 0.0;
  mesh::SheetMesh sheet;
  for (const auto& p : imported->vertices) {
    sheet.pattern.emplace_back((p - centre).dot(u), (p - centre).dot(v));
    sheet.positions.push_back(p);
    extent = std::max(extent, (p - centre).norm());
    deviation = std::max(deviation, std::abs((p - centre).dot(normal)));
  }
  if (deviation > 1e-4 * std::max(extent, 1e-9))
    throw InputError(scene.file, "[sheet] pattern_mesh '" + s.patternMesh +
                                     "' is not flat (deviates " + std::to_string(deviation) +
                                     " m from its plane)");
  Vec2 lo = sheet.pattern.front();
  for (const auto& p : sheet.pattern) lo = lo.cwiseMin(p);
  for (auto& p : sheet.pattern) p -= lo;
  for (auto t : imported->triangles) {
    // Orient every triangle counter-clockwise in the pattern.
    const Vec2 e1 = sheet.pattern[static_cast<std::size_t>(t[1])] -
                    sheet.pattern[static_cast<std::size_t>(t[0])];
    const Vec2 e2 = sheet.pattern[static_cast<std::size_t>(t[2])] -
                    sheet.pattern[static_cast<std::size_t>(t[0])];
    if (e1.x() * e2.y() - e1.y() * e2.x() < 0.0) std::swap(t[1], t[2]);
    sheet.triangles.push_back(t);
  }
  sheet.regionOfTriangle.assign(sheet.triangles.size(), 0);
  sheet.regionTypes = {mesh::RegionType::Flat};
  if (const auto problem = mesh::validate(sheet); !problem.empty())
    throw InputError(scene.file, "[sheet] pattern_mesh '" + s.patternMesh + "': " + problem);
  return sheet;
}

namespace {

// summary.json, and for a farm's log (not a terminal) the same JSON on one
// final `SUMMARY {...}` line after the PROGRESS lines (issue 8, item 6).
void writeSummary(const io::SceneSpec& scene, const ShotReport& report,
                  const ShotOptions& options) {
  const std::string json = summaryJson(scene, report);
  writeTextAtomically(report.summaryPath, json);
  const bool terminal = options.interactive < 0
                            ? options.log != nullptr && ::isatty(::fileno(options.log)) != 0
                            : options.interactive != 0;
  if (options.log != nullptr && !terminal) {
    std::fprintf(options.log, "SUMMARY %s\n", json.c_str());
    std::fflush(options.log);
  }
}

}  // namespace

ShotReport runShot(const io::SceneSpec& scene, const ShotOptions& options) {
  ShotReport report;
  report.outDir = !options.outDir.empty()     ? options.outDir
                  : !scene.output.dir.empty() ? scene.output.dir
                                              : (fs::path("out") / scene.name).string();
  FrameRange range{scene.frameStart, scene.frameEnd};
  if (options.frames) {
    validateRange(scene, *options.frames);
    range = *options.frames;
  }
  const bool render = options.render && scene.output.frames;
  if (options.checkpointEvery < 0)
    throw InputError("--checkpoint-every", "must be a number of frames >= 1");

  // Everything that can be wrong with the input is checked before any output
  // is written: no partial cache or frames that look valid.
  std::unique_ptr<io::AnimationScene> animation;
  if (!scene.animationFile.empty()) {
    animation = std::make_unique<io::AnimationScene>(io::AnimationScene::load(scene.animationFile));
    io::checkAnimationNodes(scene, *animation);
  }
  // What a checkpoint records of the files read (docs/CHECKPOINT.md), hashed as they were read.
  const std::vector<ShotInput> inputs =
      options.checkpointEvery > 0 || options.resume ? shotInputs(scene) : std::vector<ShotInput>{};
  const double t0 = frameTime(scene, scene.frameStart);
  const bool hybridModel = scene.model.type == io::ModelSpec::Type::Hybrid;
  sim::SimParams params;
  params.gravity = scene.sim.gravity;
  params.massDamping = scene.sim.massDamping;
  params.stiffnessDamping = scene.sim.stiffnessDamping;
  params.maxNewtonIterations = scene.sim.maxNewtonIterations;
  params.recoverFailedSteps = true;  // issue 9: before a shot stops on a failed step
  const std::uint64_t seed = options.seed.value_or(scene.seed);
  std::unique_ptr<paper::HybridSheet> hybrid;
  mesh::SheetMesh sheet;
  if (hybridModel) {
    hybrid = std::make_unique<paper::HybridSheet>(hybridStartSheet(scene, animation.get(), t0).mesh,
                                                  materialOf(scene.paper), params,
                                                  crumpleParamsOf(scene.model.hybrid), seed);
    sheet = hybrid->physical().mesh;
  } else {
    sheet = buildSheet(scene, animation.get());
  }
  HandleRig rig(scene, animation.get(), sheet, t0);
  rig.snap(t0, sheet.positions);
  if (hybrid) {
    std::vector<sim::Pin> start;
    rig.pins(t0, start);
    hybrid->placeVertices(start);
    hybrid->setTime(t0);
    // A finger's grip is as firm as the sheet itself (the coarse FEM's).
    hybrid->setGrips([&rig, k = hybrid->elastic().inPlaneStiffness()](
                         double t, std::vector<sim::Grip>& out) { rig.grips(t, k, out); });
    hybrid->setRebuildCallback(
        [&rig](const mesh::SheetMesh& sp, double t) { rig.rebindTangents(sp, t); });
    if (options.projectionProbe) hybrid->setProjectionCallback(options.projectionProbe);
  }
  for (int f = scene.frameStart; f <= range.last; ++f)
    (void)cameraAt(scene, animation.get(), frameTime(scene, f));
  // The look travels in the cache (texture, mesh props), read and checked now.
  const std::vector<cache::ExtensionBlock> lookBlocks = lookHeaderBlocks(scene, animation.get());
  prepareOutputDir(report.outDir, "output");
  const OutputLock outputLock(report.outDir);  // one writer per folder, until the shot is done
  report.cachePath = (fs::path(report.outDir) / "cache.pcache").string();
  if (animation)
    for (const auto& w : animation->warnings())
      report.warnings.push_back(animation->file() + ": " + w);
  report.warnings.insert(report.warnings.end(), rig.bindWarnings().begin(),
                         rig.bindWarnings().end());
  // Said now as well as in the summary: they often explain a failure that follows.
  if (options.log != nullptr)
    for (const auto& w : report.warnings) std::fprintf(options.log, "warning: %s\n", w.c_str());
  report.summaryPath = (fs::path(report.outDir) / "summary.json").string();
  std::unique_ptr<detail::FrameRenderer> renderer;
  std::optional<OutputLock> framesLock;
  if (render) {
    report.framesDir = (fs::path(report.outDir) / "frames").string();
    prepareOutputDir(report.framesDir, "frames");
    framesLock.emplace(report.framesDir);
    renderer = std::make_unique<detail::FrameRenderer>(
        scene, lookBlocks, report.framesDir, options.debugStructure, options.rendering, seed);
    report.renderBackend = backendName(options.rendering.backend);
  }

  std::optional<sim::ElasticSheet> elastic;
  if (!hybrid) elastic.emplace(sheet, materialOf(scene.paper), params);
  // Contacts (issue 5): none of it runs without colliders and with [contact] self = false.
  SceneColliders colliders(scene, animation.get());
  const sim::ContactOptions contact = contactOptionsOf(scene, colliders);
  const bool contactsOn = !colliders.empty() || contact.self != sim::SelfContactMode::Off;
  report.contactsOn = contactsOn;
  report.selfContactMode = contact.self == sim::SelfContactMode::On    ? "on"
                           : contact.self == sim::SelfContactMode::Off ? "off"
                                                                       : "auto";
  // Fingers that hold patches ([[handles]] patch_radius) grip as firmly as
  // the sheet itself.
  const auto holdGrips = [&rig](sim::ElasticSheet& model) {
    model.setGrips([&rig, k = model.inPlaneStiffness()](double t, std::vector<sim::Grip>& out) {
      rig.grips(t, k, out);
    });
  };
  if (elastic) elastic->setContacts(contact);
  if (elastic) holdGrips(*elastic);
  if (hybrid) hybrid->setContacts(contact);
  // Tearing (issue 6): runs only when the scene enables it.
  std::optional<tear::Tearing> tearing;
  if (scene.tear.enabled) {
    tearing.emplace(sheet, tearingParamsFor(scene, hybrid != nullptr), seed);
    report.tearingOn = true;
  }

  // Sound events (issue 7): detected only for a scene with [sound].
  std::optional<sound::EventDetector> soundEvents;
  if (scene.sound.enabled) {
    soundEvents.emplace(eventParamsOf(scene.sound));
    report.soundOn = true;
  }

  cache::CacheHeader header;
  header.fps = scene.fps;
  header.frameStart = scene.frameStart;
  header.frameEnd = range.last;
  header.substeps = scene.substeps;
  header.seed = seed;
  header.sceneName = scene.name;
  header.sceneFile = scene.file;
  header.sceneText = scene.sourceText;
  header.sheetWidth = scene.sheet.kind == io::SheetSpec::Kind::Rectangle ? scene.sheet.width : 0.0;
  header.sheetHeight =
      scene.sheet.kind == io::SheetSpec::Kind::Rectangle ? scene.sheet.height : 0.0;
  header.paperName = scene.paper.name;
  header.paperThickness = scene.paper.thickness;
  for (const auto& h : rig.handles()) header.handleNames.push_back(h.name);
  header.extensions = lookBlocks;
  if (contactsOn) header.extensions.push_back(cache::encodeColliders(colliders.info()));
  if (soundEvents) {
    const sound::EventParams& p = soundEvents->params();
    header.extensions.push_back(cache::encodeSoundSetup(
        {p.gridSpacing, p.curvatureThreshold, p.maxDihedral, p.freeBorderRadius, p.minSlideSpeed,
         p.minFreeBorder, p.maxTearGap}));
  }
  // Resume (issue 8): the checkpoint says which frame the state is at and
  // how many cached frames go with it; the cache keeps those and goes on.
  const std::string checkpointPath = (fs::path(report.outDir) / kCheckpointFile).string();
  std::optional<Checkpoint> resumed;
  if (options.resume) resumed = readCheckpoint(checkpointPath, scene, inputs, seed, range.last);
  std::unique_ptr<cache::CacheWriter> writer =
      resumed ? cache::CacheWriter::resume(report.cachePath, header, resumed->cachedFrames)
              : std::make_unique<cache::CacheWriter>(report.cachePath, header);

  cache::FrameRecord record;
  record.triangles = sheet.triangles;
  record.regionOfTriangle = sheet.regionOfTriangle;
  for (auto t : sheet.regionTypes) record.regionTypes.push_back(static_cast<std::uint8_t>(t));
  record.pattern = sheet.pattern;
  report.vertices = sheet.vertexCount();
  report.triangles = sheet.triangleCount();

  const long frameCount = range.last - scene.frameStart + 1;
  Progress progress(render ? "crumple run" : "crumple simulate", frameCount, options.log,
                    options.interactive);
  const double dt = 1.0 / (scene.fps * scene.substeps);
  const sim::PinFunction pins = [&rig](double t, std::vector<sim::Pin>& out) { rig.pins(t, out); };

  // The contacts of a frame whose elastic model was rebuilt by a tear
  // (vertex indices survive a cut).
  std::optional<std::vector<sim::ContactSample>> carriedContacts;
  // The baked tear textures (TEAR block) of the current mesh, re-baked when a
  // tear advances (thesis 3.3.4).
  std::optional<cache::ExtensionBlock> tearAtlasBlock;
  // The crumpling model's structure changes of the frame being emitted.
  std::optional<cache::ExtensionBlock> structureBlock;
  mesh::SheetMesh bakedSheet;  // the triangles and pattern tearAtlasBlock refers to
  const auto noteRecovery = [&](const sim::StepStats& stats, int frame) {
    for (auto [happened, span] : {std::pair{stats.newtonRetried, &report.newtonRetried},
                                  std::pair{stats.selfContactDropped, &report.selfContactDropped}})
      if (happened > 0) {
        if (span->first < 0) span->first = frame;
        span->last = frame;
      }
  };
  const auto stabilityWarnings = [&] {
    if (const auto& span = report.newtonRetried; span.first >= 0)
      report.warnings.push_back("the elastic solve needed " +
                                std::to_string(sim::kRetryIterationFactor) +
                                " times [sim] max_newton_iterations at frames " +
                                std::to_string(span.first) + "-" + std::to_string(span.last));
    if (const auto& span = report.selfContactDropped; span.first >= 0)
      report.warnings.push_back(
          "the elastic solve failed with self-contact and went on without it at frames " +
          std::to_string(span.first) + "-" + std::to_string(span.last) +
          ": the sheet may pass through itself there");
    if (report.elasticHeldStill > 0)
      report.warnings.push_back(
          "the self-contact guard held the whole sheet still on " +
          std::to_string(report.elasticHeldStill) + " animation steps at frames " +
          std::to_string(report.elasticHeldFirst) + "-" + std::to_string(report.elasticHeldLast) +
          ": not even 1/64 of the elastic step's move kept the crumpling model's mesh from "
          "passing through itself, and its handles lag there (docs/CRUMPLING.md \"A crossing "
          "that stops the whole sheet\")");
    for (const auto& h : report.handleLags) {
      if (h.frames == 0) continue;
      char text[400];
      std::snprintf(text, sizeof text,
                    "handle '%s' lags behind its node on %d frames from frame %d, up to %.3g mm "
                    "at frame %d: the sheet cannot follow there without stretching over [model] "
                    "max_edge_strain%s",
                    h.name.c_str(), h.frames, h.firstFrame, 1e3 * h.max, h.maxFrame,
                    report.elasticHeldStill > 0 ? " or passing through itself" : "");
      report.warnings.push_back(text);
    }
    for (const auto& [h, span] : report.beyondReach) {
      char text[320];
      std::snprintf(text, sizeof text,
                    "handle '%s' is pulled beyond the sheet's reach at frames %d-%d (up to %.3g m "
                    "past it): it stops on the reach and lags behind its node there",
                    rig.handles()[h].name.c_str(), span.first, span.last, span.most);
      report.warnings.push_back(text);
    }
  };
  auto emit = [&](int frame) {
    const double t = frameTime(scene, frame);
    record.frame = frame;
    record.time = t;
    if (hybrid) {
      // S_P of this frame (its topology changes as the sheet crumples) and
      // the structure of S_G (paper Fig. 2), whose vertices are S_P's first.
      const mesh::SheetMesh& sp = hybrid->physical().mesh;
      record.triangles = sp.triangles;
      record.regionOfTriangle = sp.regionOfTriangle;
      record.regionTypes.clear();
      for (auto type : sp.regionTypes)
        record.regionTypes.push_back(static_cast<std::uint8_t>(type));
      record.pattern = sp.pattern;
      record.positions = sp.positions;
      const paper::GeometricMesh& sg = hybrid->geometric();
      record.singularVertices.clear();
      for (std::size_t i = 0; i < sg.vertices.size(); ++i)
        if (sg.vertices[i].singular) record.singularVertices.push_back(static_cast<int>(i));
      record.junctionVertices = paper::junctionVertices(sg);
      record.rulings.clear();
      for (const auto& region : sg.regions)
        for (const auto& r : region.rulings) record.rulings.push_back({r.a, r.b});
      report.maxTriangles = std::max(report.maxTriangles, sp.triangleCount());
      report.singularVertices = hybrid->singularVertexCount();
      report.interiorSingularVertices = hybrid->interiorSingularVertexCount();
    } else {
      if (tearing) {  // the topology changes where the sheet tears
        // A crumpling-model sheet that tore keeps its singular vertices
        // (same indices); its rulings and junctions are no longer tracked.
        record.rulings.clear();
        record.junctionVertices.clear();
        record.triangles = sheet.triangles;
        record.regionOfTriangle = sheet.regionOfTriangle;
        record.regionTypes.clear();  // a handed-over sheet's are the elastic mesh's, not S_P's
        for (auto type : sheet.regionTypes)
          record.regionTypes.push_back(static_cast<std::uint8_t>(type));
        record.pattern = sheet.pattern;
        report.maxTriangles = std::max(report.maxTriangles, sheet.triangleCount());
      }
      record.positions = elastic->positions();
    }
    record.handleVertices.clear();
    record.handleTargets.clear();
    for (std::size_t h = 0; h < rig.handles().size(); ++h) {
      const auto& bound = rig.handles()[h];
      const bool held = !(bound.releases && t >= bound.releaseTime);
      record.handleVertices.push_back(held ? bound.vertex : -1);
      record.handleTargets.push_back(rig.target(h, t));
      // A node beyond the sheet's reach (issue 9): the handle lags behind it.
      if (const double excess = rig.reachExcess(h, t); excess > 0.0) {
        ShotReport::BeyondReach& span = report.beyondReach[h];
        if (span.first < 0) span.first = frame;
        span.last = frame;
        span.most = std::max(span.most, excess);
      }
    }
    record.camera = cameraAt(scene, animation.get(), t);
    record.extensions.clear();
    if (auto motions = propMotionBlock(scene, animation.get(), t))
      record.extensions.push_back(std::move(*motions));
    if (tearAtlasBlock) record.extensions.push_back(*tearAtlasBlock);
    if (structureBlock) record.extensions.push_back(*structureBlock);
    record.tearCount = tearing ? static_cast<std::uint32_t>(tearing->startKinds().size()) : 0;
    std::vector<cache::ContactRecord> touching;
    if (contactsOn) {
      // What the sheet touches at the end of the frame (the sound module's input).
      const auto& samples = hybrid            ? hybrid->contacts()
                            : carriedContacts ? *carriedContacts
                                              : elastic->contacts();
      touching.reserve(samples.size());
      for (const auto& c : samples)
        touching.push_back({c.vertex, c.collider < 0 ? cache::kSelfContact : c.collider,
                            static_cast<float>(c.slideSpeed), static_cast<float>(c.normalForce)});
      if (!touching.empty()) record.extensions.push_back(cache::encodeContacts(touching));
      report.contactSamples += static_cast<long>(touching.size());
      const auto depthStart = Clock::now();
      const double depth = contactDepth(contact, record);
      report.stages["contact check"].totalMs += msSince(depthStart);
      report.stages["contact check"].frames += 1;
      if (depth > report.maxContactDepth) {
        report.maxContactDepth = depth;
        report.maxContactDepthFrame = frame;
      }
    }
    if (soundEvents) {
      // The frame's sound events and their resonators (thesis 4.3.2), in the cache.
      const auto soundStart = Clock::now();
      mesh::SheetMesh surface;
      surface.pattern = record.pattern;
      surface.positions = record.positions;
      surface.triangles = record.triangles;
      surface.regionOfTriangle = record.regionOfTriangle;
      for (auto type : record.regionTypes)
        surface.regionTypes.push_back(static_cast<mesh::RegionType>(type));
      sound::SheetFrame input;
      input.mesh = &surface;
      input.rulings = record.rulings;
      input.developableRegions = hybrid != nullptr;
      for (int v : record.handleVertices)
        if (v >= 0) input.heldVertices.push_back(v);
      for (const auto& c : touching) input.contacts.push_back({c.vertex, c.slideSpeed});
      for (const auto& a : report.tearAdvances)
        if (a.frame == frame)
          input.tearAdvances.push_back({a.event.tear, a.event.from, a.event.to});
      input.time = t;
      input.frameDuration = 1.0 / scene.fps;
      std::vector<sound::SoundEvent> events;
      try {
        events = soundEvents->detect(input);
      } catch (const std::exception& e) {
        throw NumericalError("sound events", frame, e.what());
      }
      if (!events.empty()) {
        std::vector<cache::SoundEventRecord> records;
        for (const auto& e : events) {
          records.push_back(soundEventRecord(e));
          ++report.soundEvents[static_cast<std::size_t>(e.kind)];
        }
        record.extensions.push_back(cache::encodeSoundEvents(records));
      }
      report.stages["sound events"].totalMs += msSince(soundStart);
      report.stages["sound events"].frames += 1;
    }
    auto start = Clock::now();
    writer->append(record);
    report.stages["cache"].totalMs += msSince(start);
    report.stages["cache"].frames += 1;
    const auto m = measureFrame(record);
    report.maxHandleError = std::max(report.maxHandleError, m.handleError);
    report.maxStrain = std::max(report.maxStrain, m.maxStrain);
    report.meanCMean += m.cMean;
    if (m.cMean > report.maxCMean) report.maxCMeanFrame = frame;
    report.maxCMean = std::max(report.maxCMean, m.cMean);
    report.maxNComp = std::max(report.maxNComp, m.nComp);
    ++report.framesSimulated;
    if (renderer && frame >= range.first) {
      start = Clock::now();
      renderer->render(record);
      report.stages["render"].totalMs += msSince(start);
      report.stages["render"].frames += 1;
      ++report.framesRendered;
    }
    progress.update(frame - scene.frameStart + 1);
  };

  // The tearing stage of a frame (thesis 3.3, Fig. 3.14), after its elastic
  // substeps: candidates tested with the step's membrane forces, the mesh
  // cut where E_r >= E_f, and the elastic model rebuilt on the cut mesh with
  // the velocities carried over.
  const auto tearFrame = [&](int frame) {
    const auto start = Clock::now();
    // The sheet the frame ended with: the elastic model's mesh, or the
    // crumpling model's S_P (whose junction vertices are candidates too).
    const sim::ElasticSheet& model = hybrid ? hybrid->elastic() : *elastic;
    std::vector<int> junctions;
    if (hybrid) {
      sheet = hybrid->physical().mesh;
      junctions = paper::junctionVertices(hybrid->geometric());  // S_G vertices are S_P's first
      // S_P was rebuilt by the frame's animation steps: its tips and lips again.
      try {
        tearing->rebind(sheet, kLipTolerance);
      } catch (const std::exception& e) {
        throw NumericalError("tear", frame, e.what());
      }
    }
    sheet.positions = model.positions();
    std::vector<char> held(sheet.vertexCount(), 0);
    std::vector<sim::Pin> holding;
    rig.pins(frameTime(scene, frame), holding);
    for (const auto& pin : holding) held[static_cast<std::size_t>(pin.vertex)] = 1;
    // Forces in units of k_s h (tear::TearParams::resistance): E_r is strain-like.
    const double unit = materialOf(scene.paper).stretchStiffness() * tearing->edgeLength();
    const tear::VertexForces forces = [&](int v) {
      std::vector<tear::TriangleForce> out;
      for (const auto& f : model.membraneForcesOn(v)) out.push_back({f.triangle, f.force / unit});
      return out;
    };
    tear::TearFrameResult r;
    try {
      r = tearing->step(sheet, junctions, held, forces);
    } catch (const std::exception& e) {
      throw NumericalError("tear", frame, e.what());
    }
    // Developer trace (docs/TEARING.md): every candidate's Griffith test.
    if (const char* trace = std::getenv("CRUMPLE_DEBUG_TEAR"); trace != nullptr && trace[0] == '1')
      for (const auto& t : r.tests) {
        const Vec2& at = sheet.pattern[static_cast<std::size_t>(t.candidate.vertex)];
        std::fprintf(stderr,
                     "tear: frame %d vertex %d (%s) at [%.5f, %.5f]: E_r %.4g, E_f %.4g, theta "
                     "%.3f, direction [%.3f, %.3f]%s\n",
                     frame, t.candidate.vertex, tearKindName(t.candidate.kind), at.x(), at.y(),
                     t.propagation.energyRelease, t.fractureEnergy, t.propagation.angle,
                     t.propagation.direction.x(), t.propagation.direction.y(),
                     t.tears ? " tears" : "");
      }
    if (const char* trace = std::getenv("CRUMPLE_DEBUG_TEAR"); trace != nullptr && trace[0] == '1')
      for (const auto& why : r.skipped)
        std::fprintf(stderr, "tear: frame %d not cut: %s\n", frame, why.c_str());
    if (r.changed()) {
      std::vector<tear::TearEvent> events = r.events;
      carriedContacts = hybrid ? hybrid->contacts() : model.contacts();
      // The crumpling model: the advances cut S_G (thesis 3.3.3 "Remeshing"),
      // S_P is rebuilt from it, and the model goes on with the torn sheet.
      bool cutInGeometric = false;
      if (hybrid && std::none_of(r.events.begin(), r.events.end(),
                                 [](const tear::TearEvent& e) { return e.separated; })) {
        const auto& segments = tearing->segments();
        const std::size_t first = segments.size() - r.events.size();
        std::vector<paper::HybridSheet::TearAdvance> advances;
        for (std::size_t k = 0; k < r.events.size(); ++k) {
          paper::HybridSheet::TearAdvance a;
          a.from = r.events[k].from;
          a.to = r.events[k].to;
          for (std::size_t j = first + k; !r.events[k].started && j-- > 0;)
            if (segments[j].tear == r.events[k].tear) {
              a.previousDirection = (segments[j].cut.back() - segments[j].cut.front()).normalized();
              break;
            }
          advances.push_back(a);
        }
        std::string why = "it would come apart in pieces";
        try {
          paper::GeometricCutOptions cutOptions;
          cutOptions.kerf = kTearKerf;
          if (const auto cuts = hybrid->tear(advances, cutOptions)) {
            std::vector<std::vector<Vec2>> lines;
            for (const auto& c : *cuts) {
              lines.push_back(c.cut);
              report.tearRegionsFlattened += c.regionsFlattened;
            }
            tearing->recut(lines);
            sheet = hybrid->physical().mesh;
            tearing->rebind(sheet, kLipTolerance);
            for (std::size_t k = 0; k < events.size(); ++k) {
              events[k].from = lines[k].front();
              events[k].to = lines[k].back();
            }
            report.tearGeometricCuts += static_cast<int>(cuts->size());
            cutInGeometric = true;
          }
        } catch (const std::exception& e) {
          why = e.what();
        }
        if (!cutInGeometric)
          report.notes.push_back("frame " + std::to_string(frame) +
                                 ": the crumpling model's geometric layer could not take the "
                                 "tear (" +
                                 why + ")");
      }
      if (hybrid && !cutInGeometric) {
        // S_G is one piece with one outline (docs/TEARING.md): a sheet torn
        // apart goes on as the elastic model on the scene's rectangle mesh,
        // placed and moving as S_P, all its tears made again on it, its
        // handles on the vertices nearest their points.
        std::vector<tear::TearEvent> all;
        for (const auto& a : report.tearAdvances) all.push_back(a.event);
        all.insert(all.end(), r.events.begin(), r.events.end());
        std::vector<int> spHandles;
        for (const auto& h : rig.handles()) spHandles.push_back(h.vertex);
        const mesh::SheetMesh& sp = hybrid->physical().mesh;
        std::optional<ResampledSheet> resampled;
        std::optional<tear::Tearing> freshTearing;
        tear::TearFrameResult replayed;
        try {
          resampled = resampleSheet(buildSheet(scene, animation.get()), sp, model.positions(),
                                    model.velocities(), spHandles);
          freshTearing.emplace(resampled->mesh, tearingParamsOf(scene.tear), seed);
          std::vector<char> fineHeld(resampled->mesh.vertexCount(), 0);
          for (int v : resampled->handleVertices) fineHeld[static_cast<std::size_t>(v)] = 1;
          replayed = freshTearing->replay(resampled->mesh, all, fineHeld);
        } catch (const std::exception& e) {
          throw NumericalError("tear handover", frame, e.what());
        }
        ResampledSheet& fine = *resampled;
        tear::Tearing& fresh = *freshTearing;
        // This frame's advances as the fine mesh took them (the earlier
        // ones are in the report already).
        events.assign(replayed.events.end() -
                          std::min<std::ptrdiff_t>(static_cast<std::ptrdiff_t>(r.events.size()),
                                                   std::ssize(replayed.events)),
                      replayed.events.end());
        sheet = std::move(fine.mesh);
        const std::vector<Vec3> velocities =
            tear::blendValues(fine.velocities, replayed.blends, replayed.relocated);
        tearing.emplace(std::move(fresh));
        rig.rebind(sheet, fine.handleVertices, frameTime(scene, frame));
        carriedContacts.reset();  // S_P's vertices: the next frame's contacts are the fine mesh's
        elastic.emplace(sheet, materialOf(scene.paper), params);
        elastic->setContacts(contact);
        holdGrips(*elastic);
        // Interpolating S_P's long thin cells does not keep the fine mesh's
        // edge lengths: it settles first, with its pins where they are, in
        // a few tiny implicit steps (kRelaxSteps of kRelaxDt), then takes
        // S_P's velocities.
        const double t = frameTime(scene, frame);
        try {
          for (int k = 0; k < kRelaxSteps; ++k)
            (void)elastic->advance(t - kRelaxDt, kRelaxDt, pins);
        } catch (const NumericalError& e) {
          throw NumericalError("tear handover", frame, e.problem());
        }
        elastic->setVelocities(velocities);
        sheet.positions = elastic->positions();
        hybrid.reset();
        report.tearHandoverFrame = frame;
        report.vertices = sheet.vertexCount();
        report.notes.push_back("frame " + std::to_string(frame) +
                               ": from there on the sheet is simulated by the elastic model on "
                               "the scene's rectangle mesh");
      } else if (!hybrid) {
        // The elastic model on the cut mesh: velocities carried over the cut,
        // each uncut hinge's rest angle and stiffness factor kept.
        const std::vector<Vec3> velocities =
            tear::blendValues(model.velocities(), r.blends, r.relocated);
        std::map<std::pair<int, int>, std::pair<double, double>> hingeState;
        for (std::size_t h = 0; h < model.hinges().size(); ++h)
          hingeState[{model.hinges()[h].v[0], model.hinges()[h].v[1]}] = {
              model.hingeRestAngle(h), model.hingeStiffnessFactor(h)};
        sim::ElasticSheet next(sheet, materialOf(scene.paper), params);
        next.setVelocities(velocities);
        next.setContacts(contact);
        rig.rebindPatches(sheet, frameTime(scene, frame));
        holdGrips(next);
        for (std::size_t h = 0; h < next.hinges().size(); ++h) {
          const auto it = hingeState.find({next.hinges()[h].v[0], next.hinges()[h].v[1]});
          if (it == hingeState.end()) continue;
          next.setHingeRestAngle(h, it->second.first);
          next.setHingeStiffnessFactor(h, it->second.second);
        }
        elastic.emplace(std::move(next));
      }
      for (const auto& e : events) {
        report.tearAdvances.push_back({frame, e});
        if (report.firstTearFrame < 0) report.firstTearFrame = frame;
      }
    }
    // The tear textures, baked again whenever the mesh they refer to changed:
    // after a cut, and every frame the crumpling model rebuilt S_P.
    if (!tearing->segments().empty() && (r.changed() || sheet.triangles != bakedSheet.triangles ||
                                         sheet.pattern != bakedSheet.pattern)) {
      const auto bakeStart = Clock::now();
      tear::TearAtlasParams atlas;
      atlas.texelSize = tearing->fibers().texelSize();
      atlas.lipTolerance = hybrid ? kLipTolerance : 0.0;
      try {
        tearAtlasBlock =
            cache::encodeTearAtlas(tear::bakeTearAtlas(sheet, tearing->segments(), atlas));
      } catch (const std::exception& e) {
        throw NumericalError("tear atlas", frame, e.what());
      }
      bakedSheet.triangles = sheet.triangles;
      bakedSheet.pattern = sheet.pattern;
      report.tearBakeMs += msSince(bakeStart);
    }
    report.tearMs += msSince(start);
    report.stages["tear"].totalMs += msSince(start);  // the atlas's baking included
    report.stages["tear"].frames += 1;
  };

  // The whole state after frame `frame` (issue 8), written atomically.
  const auto checkpoint = [&](int frame) {
    const auto start = Clock::now();
    StateWriter w;
    writeCheckpointHead(w, scene, inputs, seed, range.last, frame, writer->framesWritten());
    saveReport(w, report);
    // The model: the crumpling model's layers, or the elastic model on its
    // (possibly torn) mesh.
    w.boolean(hybrid != nullptr);
    if (hybrid) {
      hybrid->saveState(w);
    } else {
      mesh::saveSheetMesh(w, sheet);
      elastic->saveState(w);
      // A crumpling-model sheet handed over keeps its singular vertices in
      // the cache's frames (same indices).
      w.i32s(record.singularVertices);
    }
    rig.saveState(w);
    w.boolean(tearing.has_value());
    if (tearing) {
      tearing->saveState(w);
      saveTearingReport(w, report);
      w.boolean(tearAtlasBlock.has_value());
      if (tearAtlasBlock) saveBlock(w, *tearAtlasBlock);
      w.triangles(bakedSheet.triangles);
      w.vec2s(bakedSheet.pattern);
    }
    w.boolean(soundEvents.has_value());
    if (soundEvents) soundEvents->saveState(w);
    writeCheckpointFile(checkpointPath, w);
    report.stages["checkpoint"].totalMs += msSince(start);
    report.stages["checkpoint"].frames += 1;
  };
  int firstFrame = scene.frameStart + 1;
  if (resumed) {
    StateReader& in = *resumed->state;
    restoreReport(in, report, rig.handles().size());
    if (in.boolean()) {
      if (!hybrid) in.fail("holds the crumpling model's state, the scene runs the elastic model");
      hybrid->restoreState(in);
    } else {
      // The elastic model, or a crumpling-model sheet handed over to it.
      hybrid.reset();
      sheet = mesh::restoreSheetMesh(in);
      elastic.emplace(sheet, materialOf(scene.paper), params);
      elastic->setContacts(contact);
      holdGrips(*elastic);
      elastic->restoreState(in);
      sheet.positions = elastic->positions();
      record.singularVertices = in.i32s();
    }
    rig.restoreState(in);
    if (in.boolean() != tearing.has_value())
      throw InputError(checkpointPath, "was written with a different [tear] setting");
    if (tearing) {
      // Made again on the mesh the model has now: after a hand-over, with
      // the elastic model's parameters.
      tearing.emplace(hybrid ? hybrid->physical().mesh : sheet,
                      tearingParamsFor(scene, hybrid != nullptr), seed);
      tearing->restoreState(in);
      restoreTearingReport(in, report);
      if (in.boolean()) tearAtlasBlock = restoreBlock(in);
      bakedSheet.triangles = in.triangles();
      bakedSheet.pattern = in.vec2s();
    }
    if (in.boolean() != soundEvents.has_value())
      throw InputError(checkpointPath, "was written with a different [sound] setting");
    if (soundEvents) soundEvents->restoreState(in);
    if (!in.atEnd()) in.fail("trailing bytes");
    firstFrame = resumed->frame + 1;
    if (options.log != nullptr)
      std::fprintf(options.log, "resuming after frame %d (%s)\n", resumed->frame,
                   checkpointPath.c_str());
  }

  // The cost guard (cost_guard.hpp): each frame's wall-clock budget and
  // halvings, and what most likely made a stopped frame dear.
  CostGuard guard(scene.frameBudget);
  int currentFrame = firstFrame;
  Clock::time_point frameStart = Clock::now();
  long halvingsBefore = 0;
  const auto frameDone = [&](int frame) {
    guard.frameDone(
        frame, msSince(frameStart) / 1000.0, report.halvings - halvingsBefore,
        likelyCostCause(rig, record.pattern, frameTime(scene, frame), frameTime(scene, frame - 1)));
  };
  try {
    if (!resumed) emit(scene.frameStart);
    for (int frame = firstFrame; frame <= range.last; ++frame) {
      currentFrame = frame;
      frameStart = Clock::now();
      halvingsBefore = report.halvings;
      const ScopedWorkBudget frameBudget(guard.budget());
      if (hybrid) {
        // The frame's substeps are the paper's animation steps (Fig. 16):
        // each an elastic step, the geometric step, cones, S_P rebuild and
        // isometry.
        const double t = frameTime(scene, frame - 1);
        const auto stats = hybrid->advance(t, 1.0 / scene.fps, scene.substeps, pins, frame);
        report.newtonIterations += stats.elastic.newtonIterations;
        report.halvings += stats.elastic.halvings;
        noteRecovery(stats.elastic, frame);
        report.elasticRetries += stats.elasticRetries;
        report.strainLimitRuns += stats.strainLimitRuns;
        report.strainLimitCarried += stats.strainLimitCarried;
        if (stats.elasticHeldStill > 0) {
          report.elasticHeldStill += stats.elasticHeldStill;
          if (report.elasticHeldFirst < 0) report.elasticHeldFirst = frame;
          report.elasticHeldLast = frame;
        }
        if (stats.strainLimit.lag > kLagReported) ++report.lagFrames;
        if (stats.strainLimit.lag > report.maxHandleLag) {
          report.maxHandleLag = stats.strainLimit.lag;
          report.maxHandleLagFrame = frame;
          report.maxHandleLagVertex = stats.strainLimit.lagVertex;
        }
        noteHandleLags(rig, stats.strainLimit.handleLags, frame, report.handleLags);
        report.substeps += scene.substeps;
        report.contactMs += stats.elastic.contactMs + stats.ms.contacts;
        report.selfContactMs += stats.elastic.selfContactMs + stats.ms.selfContacts;
        report.selfContactSteps += stats.elastic.selfContactSteps;
        const std::pair<const char*, double> stages[] = {
            {"elastic", stats.ms.elastic},
            {"geometric", stats.ms.geometric},
            {"cones", stats.ms.cones},
            {"rebuild", stats.ms.rebuild},
            {"isometry", stats.ms.isometry},
            {"strain limit", stats.ms.strainLimit},
            {"contacts", stats.ms.contacts + stats.ms.selfContacts}};
        for (const auto& [name, ms] : stages) {
          if (!contactsOn && std::string_view(name) == "contacts") continue;
          report.stages[name].totalMs += ms;
          report.stages[name].frames += 1;
        }
        carriedContacts.reset();
        structureBlock = cache::encodeStructureChanges(structureChangesOf(stats));
        if (tearing) tearFrame(frame);
        emit(frame);
        structureBlock.reset();
        if (options.checkpointEvery > 0 &&
            (frame - scene.frameStart) % options.checkpointEvery == 0)
          checkpoint(frame);
        frameDone(frame);
        continue;
      }
      const auto start = Clock::now();
      for (int s = 0; s < scene.substeps; ++s) {
        // Substep s of frame f starts at ((f - 1) * substeps + s) * dt.
        const double t = static_cast<double>((frame - 1) * scene.substeps + s) * dt;
        try {
          const auto stats = elastic->advance(t, dt, pins);
          report.newtonIterations += stats.newtonIterations;
          report.halvings += stats.halvings;
          report.contactMs += stats.contactMs;
          report.selfContactMs += stats.selfContactMs;
          report.selfContactSteps += stats.selfContactSteps;
          noteRecovery(stats, frame);
          ++report.substeps;
        } catch (const NumericalError& e) {
          throw NumericalError(e.stage(), frame, e.problem());
        }
      }
      report.stages["elastic"].totalMs += msSince(start);
      report.stages["elastic"].frames += 1;
      carriedContacts.reset();
      if (tearing) tearFrame(frame);
      emit(frame);
      if (options.checkpointEvery > 0 && (frame - scene.frameStart) % options.checkpointEvery == 0)
        checkpoint(frame);
      frameDone(frame);
    }
  } catch (const NumericalError& caught) {
    // A frame that ran out of its budget in any stage is the cost guard's stop.
    const double budget = guard.budget();
    const bool overBudget =
        budget > 0.0 && msSince(frameStart) / 1000.0 >= budget && caught.stage() != "cost guard";
    const NumericalError e =
        overBudget
            ? guard.budgetError(currentFrame, caught.stage(),
                                likelyCostCause(rig, record.pattern, frameTime(scene, currentFrame),
                                                frameTime(scene, currentFrame - 1)))
            : caught;
    progress.finish();
    report.error = e.what();
    report.hybrid = hybridModel;
    if (report.framesSimulated > 0) report.meanCMean /= report.framesSimulated;
    writer->close();  // the cache stays valid up to the last good frame
    stabilityWarnings();
    writeSummary(scene, report, options);
    throw e;
  }
  progress.finish();
  writer->close();
  if (tearing) {
    report.tearSegments = tearing->segments();
    report.tearStartKinds = tearing->startKinds();
  }
  if (soundEvents) report.soundResonatorMs = soundEvents->resonatorMs();
  if (render && soundEvents) {
    // `run`: the soundtrack too, before the movie that muxes it in.
    SoundOptions soundOptions;
    soundOptions.log = options.log;
    soundOptions.interactive = options.interactive;
    soundOptions.lockFolder = false;  // sound.wav goes beside the cache: outputLock's folder
    const SoundReport made = makeSound(report.cachePath, soundOptions);
    report.soundPath = made.wavPath;
    report.stages["sound"].totalMs += made.synthesisMs;
    report.stages["sound"].frames += made.frames;
  }
  if (renderer && report.framesRendered > 0)
    finishFrames(report.framesDir, FrameRange{std::max(range.first, scene.frameStart), range.last},
                 scene.fps, report.outDir, options.rendering, report.contactSheetPath,
                 report.moviePath, report.notes);
  report.hybrid = hybridModel;
  if (report.framesSimulated > 0) report.meanCMean /= report.framesSimulated;
  if (hybridModel && report.maxCMean > kLengthErrorWarning) {
    char text[256];
    std::snprintf(
        text, sizeof text,
        "edge lengths deviate from the pattern by %.2f %% on average at frame %d (c_mean; the "
        "crumpling model aims below 0.5 %%): the paper stretches or shrinks visibly there",
        100.0 * report.maxCMean, report.maxCMeanFrame);
    report.warnings.push_back(text);
  }
  stabilityWarnings();
  if (report.halvings > 0)
    report.warnings.push_back("the elastic solve halved its substep " +
                              std::to_string(report.halvings) +
                              " times; consider more [scene] substeps");
  writeSummary(scene, report, options);
  return report;
}

RenderReport renderCache(const std::string& cachePath, const RenderOptions& options) {
  const cache::CacheReader reader(cachePath);
  if (reader.frameCount() == 0) throw InputError(cachePath, "the cache holds no frames");
  const auto& header = reader.header();
  const io::SceneSpec scene =
      io::parseScene(header.sceneText, header.sceneFile + " (in " + cachePath + ")",
                     fs::path(header.sceneFile).parent_path().string(),
                     /*checkFiles=*/false);
  RenderReport report;
  if (std::string note = recoveredNote(reader); !note.empty()) {
    if (options.log) std::fprintf(options.log, "crumple render: note: %s\n", note.c_str());
    report.notes.push_back(std::move(note));
  }
  report.framesDir = !options.framesDir.empty()
                         ? options.framesDir
                         : (fs::path(cachePath).parent_path() / "frames").string();
  const int firstCached = reader.readFrame(0).frame;
  const int lastCached = firstCached + static_cast<int>(reader.frameCount()) - 1;
  FrameRange range{firstCached, lastCached};
  if (options.frames) {
    range = *options.frames;
    if (range.first < firstCached || range.last > lastCached)
      throw InputError(
          cachePath, "--frames " + std::to_string(range.first) + "-" + std::to_string(range.last) +
                         " is outside the cached frames " + std::to_string(firstCached) + "-" +
                         std::to_string(lastCached));
  }
  if ((options.rendering.contactSheet || options.rendering.movie) && !options.rendering.png)
    throw InputError("--contact-sheet/--movie", "need the PNG frames (drop --no-png)");
  prepareOutputDir(report.framesDir, "frames");
  const OutputLock lock(report.framesDir,
                        options.frames ? OutputLock::Mode::Shared : OutputLock::Mode::Exclusive);
  detail::FrameRenderer renderer(scene, header.extensions, report.framesDir, options.debugStructure,
                                 options.rendering, header.seed);
  Progress progress(std::string("crumple render (") + backendName(options.rendering.backend) + ")",
                    range.last - range.first + 1, options.log, options.interactive);
  for (int f = range.first; f <= range.last; ++f) {
    const auto frame = reader.readFrame(static_cast<std::size_t>(f - firstCached));
    const auto start = Clock::now();
    renderer.render(frame);
    report.cost.totalMs += msSince(start);
    report.cost.frames += 1;
    ++report.framesRendered;
    progress.update(f - range.first + 1);
  }
  progress.finish();
  finishFrames(report.framesDir, range, scene.fps, fs::path(cachePath).parent_path().string(),
               options.rendering, report.contactSheetPath, report.moviePath, report.notes);
  return report;
}

const char* backendName(RenderSettings::Backend backend) {
  return backend == RenderSettings::Backend::Embree ? "embree" : "osmesa";
}

double ShotReport::contactShareOfStep() const {
  double step = 0.0;
  for (const char* name : {"elastic", "geometric", "cones", "rebuild", "isometry", "contacts"})
    if (const auto it = stages.find(name); it != stages.end()) step += it->second.totalMs;
  return step > 0.0 ? (contactMs + selfContactMs) / step : 0.0;
}

std::string summaryText(const ShotReport& r) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line,
                "%d frames simulated (%zu vertices, %zu triangles), %d rendered\n",
                r.framesSimulated, r.vertices, r.triangles, r.framesRendered);
  out += line;
  for (const auto& [name, cost] : r.stages) {
    std::snprintf(line, sizeof line, "  %-13s %9.2f ms/frame over %ld frames\n", name.c_str(),
                  cost.msPerFrame(), cost.frames);
    out += line;
  }
  std::snprintf(line, sizeof line,
                "  newton   %.2f iterations/substep, %ld halvings; max handle error %.3g m, max "
                "edge strain %.3g\n",
                r.substeps > 0 ? static_cast<double>(r.newtonIterations) / r.substeps : 0.0,
                r.halvings, r.maxHandleError, r.maxStrain);
  out += line;
  if (r.contactsOn) {
    const double frames = std::max(1, r.framesSimulated - 1);
    std::snprintf(line, sizeof line,
                  "  contacts %.2f ms/frame colliders + %.2f ms/frame self-contact (%s, ran in %ld "
                  "substeps): %.1f %% of the step; deepest vertex %.3f thicknesses in (frame %d)\n",
                  r.contactMs / frames, r.selfContactMs / frames, r.selfContactMode.c_str(),
                  r.selfContactSteps, 100.0 * r.contactShareOfStep(), r.maxContactDepth,
                  r.maxContactDepthFrame);
    out += line;
  }
  if (r.tearingOn) {
    const double frames = std::max(1, r.framesSimulated - 1);
    if (r.tearStartKinds.empty()) {
      std::snprintf(line, sizeof line, "  tearing  %.2f ms/frame: nothing tore\n",
                    r.tearMs / frames);
    } else {
      std::snprintf(line, sizeof line,
                    "  tearing  %.2f ms/frame: %zu tear(s), the first at frame %d, %zu tip "
                    "advances\n",
                    r.tearMs / frames, r.tearStartKinds.size(), r.firstTearFrame,
                    r.tearAdvances.size());
    }
    out += line;
  }
  if (r.soundOn) {
    std::snprintf(line, sizeof line,
                  "  sound    %ld crumpling, %ld friction, %ld tearing event(s)\n",
                  r.soundEvents[0], r.soundEvents[1], r.soundEvents[2]);
    out += line;
  }
  out += "  cache:   " + r.cachePath + "\n";
  if (!r.soundPath.empty()) out += "  sound:   " + r.soundPath + "\n";
  if (!r.framesDir.empty()) out += "  frames:  " + r.framesDir + "/\n";
  if (!r.contactSheetPath.empty()) out += "  contact sheet: " + r.contactSheetPath + "\n";
  if (!r.moviePath.empty()) out += "  movie:   " + r.moviePath + "\n";
  out += "  summary: " + r.summaryPath + "\n";
  for (const auto& n : r.notes) out += "  note: " + n + "\n";
  for (const auto& w : r.warnings) out += "  warning: " + w + "\n";
  return out;
}

std::string summaryJson(const io::SceneSpec& scene, const ShotReport& r) {
  JsonWriter j;
  j.beginObject();
  j.key("scene").value(scene.name);
  j.key("scene_file").value(scene.file);
  j.key("cache").value(r.cachePath);
  j.key("frames_dir").value(r.framesDir);
  j.key("frames_simulated").value(r.framesSimulated);
  j.key("frames_rendered").value(r.framesRendered);
  j.key("vertices").value(r.vertices);
  j.key("triangles").value(r.triangles);
  j.key("substeps_per_frame").value(scene.substeps);
  const sim::Material paper = materialOf(scene.paper);
  j.key("paper").beginObject();
  j.key("preset").value(paper.name);
  j.key("thickness_m").value(paper.thickness);
  j.key("areal_density_kg_m2").value(paper.arealDensity());
  j.key("stretch_stiffness_N_m").value(paper.stretchStiffness());
  j.key("bending_stiffness_N_m").value(paper.bendingStiffness());
  j.endObject();
  // What ran: a scene pays only for what it uses (DESIGN.md "Invariants").
  j.key("ran").beginObject();
  j.key("elastic").value(true);
  j.key("crumpling_model").value(r.hybrid);
  j.key("contacts").value(!scene.colliders.empty());
  j.key("self_contact").value(r.selfContactSteps > 0);
  j.key("tearing").value(r.tearingOn);
  j.key("sound").value(r.soundOn);
  j.key("render_osmesa").value(r.framesRendered > 0 && r.renderBackend == "osmesa");
  j.key("render_embree").value(r.framesRendered > 0 && r.renderBackend == "embree");
  j.endObject();
  j.key("ms_per_frame").beginObject();
  for (const auto& [name, cost] : r.stages) j.key(name).value(cost.msPerFrame());
  j.endObject();
  if (r.contactsOn) {
    // Issue 5: what contacts cost (detection, penalties' setup and the
    // failsafe; the Newton iterations they add are the elastic stage's) and
    // the deepest any free vertex went, measured at every frame.
    const double frames = std::max(1, r.framesSimulated - 1);
    j.key("contacts").beginObject();
    j.key("colliders").value(static_cast<long long>(scene.colliders.size()));
    j.key("self_contact_mode").value(r.selfContactMode);
    j.key("self_contact_substeps").value(static_cast<long long>(r.selfContactSteps));
    j.key("collider_ms_per_frame").value(r.contactMs / frames);
    j.key("self_contact_ms_per_frame").value(r.selfContactMs / frames);
    j.key("share_of_step").value(r.contactShareOfStep());
    j.key("contacts_per_frame")
        .value(static_cast<double>(r.contactSamples) / std::max(1, r.framesSimulated));
    j.key("max_depth_thicknesses").value(r.maxContactDepth);
    j.key("max_depth_frame").value(r.maxContactDepthFrame);
    j.endObject();
  }
  if (r.soundOn) {
    // Issue 7: the events in the cache, and the soundtrack `run` made.
    j.key("sound").beginObject();
    j.key("crumpling_events").value(static_cast<long long>(r.soundEvents[0]));
    j.key("friction_events").value(static_cast<long long>(r.soundEvents[1]));
    j.key("tearing_events").value(static_cast<long long>(r.soundEvents[2]));
    const auto events = r.stages.find("sound events");
    j.key("ms_per_frame").value(events != r.stages.end() ? events->second.msPerFrame() : 0.0);
    j.key("resonator_ms_per_frame").value(r.soundResonatorMs / std::max(1, r.framesSimulated));
    j.key("wav").value(r.soundPath);  // empty: `simulate` (crumple sound makes it)
    j.endObject();
  }
  if (r.tearingOn) {
    // Issue 6: the tears, where each started and how far it ran.
    const double frames = std::max(1, r.framesSimulated - 1);
    j.key("tearing").beginObject();
    j.key("ms_per_frame").value(r.tearMs / frames);
    j.key("bake_ms_per_frame").value(r.tearBakeMs / frames);
    j.key("first_tear_frame").value(r.firstTearFrame);
    j.key("tip_advances").value(static_cast<long long>(r.tearAdvances.size()));
    j.key("crumpling_model_cuts").value(r.tearGeometricCuts);
    j.key("curved_regions_flattened").value(r.tearRegionsFlattened);
    j.key("handover_frame").value(r.tearHandoverFrame);
    j.key("tears").beginArray();
    for (std::size_t t = 0; t < r.tearStartKinds.size(); ++t) {
      j.beginObject();
      j.key("started_at").value(tearKindName(r.tearStartKinds[t]));
      double length = 0.0, detail = 0.0;
      for (const auto& seg : r.tearSegments)
        if (seg.tear == static_cast<int>(t)) {
          length += tear::pathLength(seg.cut);
          detail += tear::pathLength(seg.detail);
        }
      j.key("cut_length_m").value(length);
      j.key("detail_length_m").value(detail);
      j.endObject();
    }
    j.endArray();
    j.endObject();
  }
  j.key("newton_iterations").value(static_cast<long long>(r.newtonIterations));
  j.key("substep_halvings").value(static_cast<long long>(r.halvings));
  j.key("max_handle_error").value(r.maxHandleError);
  j.key("max_edge_strain").value(r.maxStrain);
  if (r.hybrid) {
    // Paper Table IV measures, as fractions (c_mean 0.005 = 0.5 %).
    j.key("crumpling").beginObject();
    j.key("c_mean_mean").value(r.meanCMean);
    j.key("c_mean_max").value(r.maxCMean);
    j.key("n_comp_max").value(r.maxNComp);
    j.key("singular_vertices").value(r.singularVertices);
    j.key("interior_singular_vertices").value(r.interiorSingularVertices);
    j.key("max_triangles").value(static_cast<long long>(r.maxTriangles));
    j.key("elastic_retries").value(static_cast<long long>(r.elasticRetries));
    j.key("strain_limit_steps").value(static_cast<long long>(r.strainLimitRuns));
    j.key("strain_limit_carried_steps").value(static_cast<long long>(r.strainLimitCarried));
    j.key("elastic_steps_held_still").value(static_cast<long long>(r.elasticHeldStill));
    j.key("elastic_held_first_frame").value(static_cast<long long>(r.elasticHeldFirst));
    j.key("elastic_held_last_frame").value(static_cast<long long>(r.elasticHeldLast));
    // Handles held back so the sheet does not stretch (strain_limit.hpp).
    j.key("handle_lag_frames").value(static_cast<long long>(r.lagFrames));
    j.key("max_handle_lag").value(r.maxHandleLag);
    j.key("max_handle_lag_frame").value(static_cast<long long>(r.maxHandleLagFrame));
    j.key("max_handle_lag_vertex").value(static_cast<long long>(r.maxHandleLagVertex));
    j.key("handle_lags").beginArray();
    for (const auto& h : r.handleLags) {
      if (h.frames == 0) continue;
      j.beginObject();
      j.key("handle").value(h.name);
      j.key("frames").value(static_cast<long long>(h.frames));
      j.key("first_frame").value(static_cast<long long>(h.firstFrame));
      j.key("max_lag").value(h.max);
      j.key("max_lag_frame").value(static_cast<long long>(h.maxFrame));
      j.endObject();
    }
    j.endArray();
    j.endObject();
  }
  j.key("warnings").beginArray();
  for (const auto& w : r.warnings) j.value(w);
  j.endArray();
  j.key("error").value(r.error);
  j.endObject();
  return j.str() + "\n";
}

}  // namespace crumple::pipeline
