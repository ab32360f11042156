#pragma once
// One shot, end to end (DESIGN.md "One shot, end to end"): scene + handle
// tracks -> elastic sheet, frame by frame -> .pcache; and cache -> frames.
#include <cstdint>
#include <cstdio>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "crumple/exporters/pcache.hpp"
#include "crumple/io/animation.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/render/view.hpp"

namespace crumple::pipeline {

struct FrameRange {
  int first = 0;
  int last = 0;  // inclusive
};
// Parses "A-B" or "A"; throws InputError on anything else or B < A.
FrameRange parseFrameRange(const std::string& text);

struct ShotOptions {
  std::string outDir;                 // empty: the scene's [output] dir, else out/<name>
  std::optional<FrameRange> frames;   // simulate from the scene's first frame up to last;
                                      // render only this range
  std::optional<std::uint64_t> seed;  // overrides the scene's seed
  bool render = true;                 // `run` renders, `simulate` does not
  bool debugStructure = false;        // render the crumpling model's structure view
  std::FILE* log = stderr;            // progress and notes
  int interactive = -1;               // -1: detect a terminal on `log`
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
  std::map<std::string, StageCost> stages;  // "elastic", "cache", "render"
  std::vector<std::string> warnings;
  std::string error;  // set when the run stopped early (cache valid up to the last frame)
};

// The simulation mesh of the scene's sheet, placed in the world.
mesh::SheetMesh buildSheet(const io::SceneSpec& scene, const io::AnimationScene* animation);

// Simulates the shot and writes DIR/cache.pcache (and, with options.render,
// DIR/frames/NNNN.png), then DIR/summary.json. Bad input throws InputError
// before anything is written. A numerical failure closes the cache at the
// last good frame, writes the summary with the error, and throws
// NumericalError naming the frame and stage.
ShotReport runShot(const io::SceneSpec& scene, const ShotOptions& options);

// Renders frames of a cache with the OSMesa preview into framesDir
// (NNNN.png, each written atomically). Returns the frames written.
struct RenderOptions {
  std::optional<FrameRange> frames;  // default: all cached frames
  std::string framesDir;             // default: <cache folder>/frames
  bool debugStructure = false;  // flat/curved regions, rulings, singular, junction, handle vertices
  std::FILE* log = stderr;
  int interactive = -1;
};
struct RenderReport {
  std::string framesDir;
  int framesRendered = 0;
  StageCost cost;
};
RenderReport renderCache(const std::string& cachePath, const RenderOptions& options);

// The render view of a scene for one cached frame.
render::RenderScene makeRenderScene(const io::SceneSpec& scene, const cache::CameraRecord& camera);

// Closing summary line(s) for the terminal, and summary.json text.
std::string summaryText(const ShotReport& report);
std::string summaryJson(const io::SceneSpec& scene, const ShotReport& report);

}  // namespace crumple::pipeline
