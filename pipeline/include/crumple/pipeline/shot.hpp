#pragma once
// One shot, end to end (docs/ARCHITECTURE.md "One shot, end to end"): scene + handle
// tracks -> elastic sheet, frame by frame -> .pcache; and cache -> frames.
#include <array>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/cache/pcache_motion.hpp"
#include "crumple/io/animation.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/mesh/developable.hpp"
#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/render/aov.hpp"
#include "crumple/render/view.hpp"
#include "crumple/tear/tearing.hpp"

namespace crumple::paper {
struct ProjectionInput;  // crumple/paper/hybrid_sheet.hpp
}  // namespace crumple::paper

namespace crumple::pipeline {

struct FrameRange {
  int first = 0;
  int last = 0;  // inclusive
};
// Parses "A-B" or "A"; throws InputError on anything else or B < A.
FrameRange parseFrameRange(const std::string& text);

// How frames are rendered (`run` and `render`).
struct RenderSettings {
  enum class Backend { Osmesa, Embree };
  Backend backend = Backend::Osmesa;
  int samplesPerPixel = 16;  // Embree
  int maxBounces = 4;        // Embree
  render::RenderPass pass = render::RenderPass::Beauty;
  bool png = true;   // NNNN.png (8-bit sRGB, straight alpha)
  bool exr = false;  // NNNN.exr (linear, premultiplied alpha)
  // Embree: AOV channels in NNNN.exr beside RGBA (render/aov.hpp); not
  // empty writes the EXR whatever `exr` says.
  std::vector<render::Aov> aovs;
  // The crumpling model's curved regions refined (refine.hpp); nullopt: auto
  // for embree, off for osmesa. Off under the structure view.
  std::optional<mesh::RefineOptions> refine;
  // Embree: the motion blur's shutter (`render --shutter`); nullopt: the
  // one the cache was simulated for (FrameViewBuilder). An open shutter
  // needs a cache with sub-frame motion (InputError otherwise).
  std::optional<cache::Shutter> shutter;
  bool contactSheet = false;  // contact_sheet.png in the shot's folder (beside the cache)
  bool movie = false;         // preview.mp4 there through ffmpeg, with its sound.wav if any
};
const char* backendName(RenderSettings::Backend backend);

struct ShotOptions {
  std::string outDir;                 // empty: the scene's [output] dir, else out/<name>
  std::optional<FrameRange> frames;   // simulate from the scene's first frame up to last;
                                      // render only this range
  std::optional<std::uint64_t> seed;  // overrides the scene's seed
  bool render = true;                 // `run` renders, `simulate` does not
  bool debugStructure = false;        // render the crumpling model's structure view
  RenderSettings rendering;
  std::FILE* log = stderr;  // progress and notes; nullptr: a quiet run
  int interactive = -1;     // -1: detect a terminal on `log`
  // Checkpoint and resume: every this many frames (0: never) the
  // whole simulation state goes to DIR/checkpoint.bin, atomically; `resume`
  // goes on from it, and the cache ends byte-identical to an uninterrupted
  // run's (docs/CHECKPOINT.md).
  int checkpointEvery = 0;
  bool resume = false;
  // Crumpling model: called with every isometry projection's input
  // (paper::HybridSheet::setProjectionCallback; paper Table III, bench).
  std::function<void(const paper::ProjectionInput&)> projectionProbe;
};

// Milliseconds spent per stage, summed over the frames it ran for.
struct StageCost {
  double totalMs = 0.0;
  long frames = 0;
  double msPerFrame() const { return frames > 0 ? totalMs / static_cast<double>(frames) : 0.0; }
};

struct ShotReport {
  std::string outDir;
  std::string cachePath;
  std::string framesDir;  // empty when nothing was rendered
  std::string summaryPath;
  int framesSimulated = 0;
  int framesRendered = 0;
  long newtonIterations = 0;
  long substeps = 0;
  long halvings = 0;
  long elasticRetries = 0;  // hybrid: elastic steps retried with the pins on their targets
  // Hybrid strain limit (paper/strain_limit.hpp): animation steps it had
  // work in, and in how many the carried start or the handle lag gave the
  // result; frames whose handles lag (over 1 um) and the largest lag.
  long strainLimitRuns = 0;
  long strainLimitCarried = 0;
  // Animation steps whose elastic step the crossing guard held back entirely
  // (paper::HybridStepStats::elasticHeldStill), and their first and last frame.
  long elasticHeldStill = 0;
  int elasticHeldFirst = -1, elasticHeldLast = -1;
  int lagFrames = 0;
  double maxHandleLag = 0.0;  // metres
  int maxHandleLagFrame = -1;
  int maxHandleLagVertex = -1;
  // Each handle of the scene (in scene order) and how it lagged: on how many
  // frames (over 1 um), from which frame, its largest lag and that frame.
  struct HandleLag {
    std::string name;
    int frames = 0;
    int firstFrame = -1;
    double max = 0.0;  // metres
    int maxFrame = -1;
  };
  std::vector<HandleLag> handleLags;
  // Frames whose elastic step needed more Newton iterations, or went on
  // without self-contact, after failing at every halving (first and last
  // frame, -1: none), and each handle (by index) pulled beyond the sheet's
  // reach (first and last frame, the most in metres): the warnings' record.
  struct FrameSpan {
    int first = -1, last = -1;
  };
  FrameSpan newtonRetried, selfContactDropped;
  struct BeyondReach {
    int first = -1, last = -1;
    double most = 0.0;
  };
  std::map<std::size_t, BeyondReach> beyondReach;
  // Contacts: collider and self-contact work (detection, the
  // failsafe; within the elastic stage, plus the crumpling model's failsafe
  // after its isometry), the deepest free vertex inside a collider or the
  // sheet at any frame (in thicknesses), and the contacts written to the cache.
  bool contactsOn = false;
  std::string selfContactMode;  // "on", "off" or "auto"
  double contactMs = 0.0;
  double selfContactMs = 0.0;
  long selfContactSteps = 0;  // substeps self-contact detection ran in
  double maxContactDepth = 0.0;
  int maxContactDepthFrame = 0;
  long contactSamples = 0;
  // The contacts' share of the simulation step (elastic, geometric, cones,
  // rebuild, isometry and contact stages).
  double contactShareOfStep() const;
  // The air (docs/AIR.md): whether it ran, and the time its terms took in
  // the elastic step (set-up, energy, gradient, Hessian), and their share
  // of the step.
  bool airOn = false;
  double airMs = 0.0;
  double airShareOfStep() const;
  // Tearing: whether it ran, each tip advance (frame, tear, where
  // from, E_r and E_f) and the tears' paths in the pattern at the end.
  bool tearingOn = false;
  struct TearAdvance {
    int frame = 0;
    tear::TearEvent event;
  };
  std::vector<TearAdvance> tearAdvances;
  std::vector<tear::TearSegment> tearSegments;
  std::vector<tear::CandidateKind> tearStartKinds;  // per tear
  int firstTearFrame = -1;
  // Crumpling model: advances made in S_G (the model goes on crumpling the
  // torn sheet), and the curved regions they turned flat (cases 1-2).
  int tearGeometricCuts = 0;
  int tearRegionsFlattened = 0;
  // Crumpling model: the frame from which the sheet went on as the elastic
  // model on the scene's rectangle mesh, when a tear came apart into pieces
  // (S_G is one piece) or S_G could not take a cut (-1: never).
  int tearHandoverFrame = -1;
  double tearMs = 0.0;      // candidates, Griffith tests, cuts, detail paths, baking (wall time)
  double tearBakeMs = 0.0;  // of which baking the tear textures
  // Sound: whether events were detected, how many of each kind
  // (crumpling, friction, tearing), and the soundtrack `run` wrote.
  bool soundOn = false;
  std::array<long, 3> soundEvents{};
  double soundResonatorMs = 0.0;  // of the "sound events" stage: growing the resonators
  std::string soundPath;
  std::size_t vertices = 0;
  std::size_t triangles = 0;
  double maxHandleError = 0.0;
  double maxStrain = 0.0;
  // Crumpling model (paper Table IV measures over the frames).
  bool hybrid = false;
  double meanCMean = 0.0;  // mean over frames of c_mean
  double maxCMean = 0.0;
  int maxCMeanFrame = 0;
  double maxNComp = 0.0;
  int singularVertices = 0;          // at the last frame
  int interiorSingularVertices = 0;  // at the last frame
  std::size_t maxTriangles = 0;
  std::string renderBackend;                // "osmesa" or "embree" when frames were rendered
  std::string contactSheetPath;             // empty unless asked for
  std::string moviePath;                    // empty unless asked for
  std::vector<std::string> notes;           // e.g. why there is no movie
  std::map<std::string, StageCost> stages;  // "elastic", "cache", "render"
  std::vector<std::string> warnings;
  std::string error;  // set when the run stopped early (cache valid up to the last frame)
};

// Simulates the shot and writes DIR/cache.pcache (and, with options.render,
// DIR/frames/NNNN.png), then DIR/summary.json, holding DIR's lock (and
// DIR/frames') throughout (OutputLock). Bad input, or a folder another
// crumple is writing into, throws InputError before anything is written. A
// numerical failure closes the cache at the last good frame, writes the
// summary with the error, and throws NumericalError naming the frame and
// stage.
ShotReport runShot(const io::SceneSpec& scene, const ShotOptions& options);

// Renders frames of a cache with the chosen backend into framesDir
// (NNNN.png and/or NNNN.exr, each written atomically), then the contact sheet
// and the movie when asked. Returns the frames written. Holds framesDir's
// lock (OutputLock): exclusive for the whole cache, shared for a frame range
// (a farm's array tasks render their chunks into one folder side by side).
struct RenderOptions {
  std::optional<FrameRange> frames;  // default: all cached frames
  std::string framesDir;             // default: <cache folder>/frames
  bool debugStructure = false;  // flat/curved regions, rulings, singular, junction, handle vertices
  RenderSettings rendering;
  std::FILE* log = stderr;  // progress; nullptr: a quiet run
  int interactive = -1;
};
struct RenderReport {
  std::string framesDir;
  int framesRendered = 0;
  StageCost cost;
  std::string contactSheetPath;    // empty unless asked for
  std::string moviePath;           // empty unless asked for
  std::vector<std::string> notes;  // e.g. "no soundtrack yet: the movie is silent"
};
RenderReport renderCache(const std::string& cachePath, const RenderOptions& options);

// The render view of a scene for one cached frame.
render::RenderScene makeRenderScene(const io::SceneSpec& scene, const cache::CameraRecord& camera);

// What the renderers draw for one cached frame: the view (camera, lights,
// environment, ground, paper look with its texture, props, this frame's sharp
// vertices) and the sheet. Built once per shot from the scene and the cache
// header's extension blocks (the paper texture and the mesh props' rest
// meshes, lookHeaderBlocks), then once per frame (the props' motions come
// from the frame's block, propMotionBlock): rendering needs nothing but the
// cache. Keeps a reference to `scene`. Throws CorruptDataError on malformed
// blocks, InputError on a texture that is not a PNG.
//
// With refinement on (`refine`, mesh/developable.hpp), a frame of the
// crumpling model (its SGEO block) gets its curved regions refined: Auto
// measures the density on the frame's camera; the tear patches follow their
// triangles.
//
// Motion blur (docs/RENDERING.md "Motion blur"): with a shutter, the view's
// sheetMotion and its moving mesh props' motion hold their positions at the
// shutter's opening and closing, from the frame's velocities (VELO, PRPV).
// The shutter is the one the cache was simulated for (its header's SHTR;
// none without); setShutter replaces it (closed: every frame sharp).
struct FrameView {
  render::RenderScene scene;
  mesh::SheetMesh sheet;
  std::optional<mesh::RefineStats> refined;  // the refinement's figures, when it ran
};
class FrameViewBuilder {
 public:
  FrameViewBuilder(const io::SceneSpec& scene,
                   const std::vector<cache::ExtensionBlock>& headerBlocks,
                   const mesh::RefineOptions& refine = offRefinement());
  FrameView build(const cache::FrameRecord& frame) const;
  static mesh::RefineOptions offRefinement() {
    mesh::RefineOptions o;
    o.mode = mesh::RefineMode::Off;
    return o;
  }
  void setShutter(const cache::Shutter& shutter) { shutter_ = shutter; }
  const cache::Shutter& shutter() const { return shutter_; }

 private:
  const io::SceneSpec& scene_;
  mesh::RefineOptions refine_;
  ImageRGBA8 texture_;
  std::vector<render::PropMesh> boxes_;
  std::vector<render::PropMesh> meshPropsAtRest_;
  cache::Shutter shutter_;
};

// The cache header's look blocks (docs/PCACHE.md): "PTEX", the [paper]
// texture file's PNG bytes; "PROP", the rest meshes (world space at t = 0) of
// the [[props]] mesh nodes. Throws InputError (scene file and line) for an
// unreadable texture or a node without a mesh.
std::vector<cache::ExtensionBlock> lookHeaderBlocks(const io::SceneSpec& scene,
                                                    const io::AnimationScene* animation);
// A frame's "PRPM" block: each mesh prop's motion from its rest mesh at time
// t (s); nullopt when the scene has no mesh props.
std::optional<cache::ExtensionBlock> propMotionBlock(const io::SceneSpec& scene,
                                                     const io::AnimationScene* animation, double t);

// Closing summary line(s) for the terminal, and summary.json text.
std::string summaryText(const ShotReport& report);
std::string summaryJson(const io::SceneSpec& scene, const ShotReport& report);

}  // namespace crumple::pipeline
