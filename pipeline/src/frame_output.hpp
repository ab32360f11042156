#pragma once
// Rendering a shot's frames to files (pipeline-internal): one renderer per
// shot (OSMesa preview or Embree path tracer), atomic frame-numbered files,
// the contact sheet and the ffmpeg movie preview.
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/pipeline/shot.hpp"

namespace crumple::pipeline::detail {

// NNNN.<extension>: the frame number with at least four digits.
std::string frameFileName(int frame, const char* extension = "png");

// Renders cached frames with one renderer reused across frames and writes
// framesDir/NNNN.png and/or NNNN.exr (each atomically). headerBlocks: the
// cache header's extension blocks (FrameViewBuilder).
class FrameRenderer {
 public:
  FrameRenderer(const io::SceneSpec& scene, const std::vector<cache::ExtensionBlock>& headerBlocks,
                std::string framesDir, bool debugStructure, const RenderSettings& settings,
                std::uint64_t seed);
  ~FrameRenderer();
  FrameRenderer(const FrameRenderer&) = delete;
  FrameRenderer& operator=(const FrameRenderer&) = delete;

  void render(const cache::FrameRecord& frame);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// framesDir/NNNN.png of the given frames, at most 36 of them evenly spaced
// (first and last included), as a grid in `path`. Returns the frames used.
std::vector<int> writeContactSheet(const std::string& framesDir, int first, int last,
                                   const std::string& path);

// The movie preview: framesDir/NNNN.png from `first` to `last` at `fps` into
// `path` (H.264 MP4) with `sound` muxed in when that file exists. Returns
// false and says why in `note` when ffmpeg is not installed or fails; `note`
// also says when the movie is silent.
bool makeMovie(const std::string& framesDir, int first, int last, double fps,
               const std::string& sound, const std::string& path, std::string& note);

}  // namespace crumple::pipeline::detail
