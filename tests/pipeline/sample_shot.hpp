#pragma once
// Simulating a sample in a scene-level test (tests/pipeline): quietly,
// without rendering, into a temporary folder.
#include <functional>
#include <string>

#include "crumple/io/scene.hpp"
#include "crumple/pipeline/shot.hpp"
#include "test_util.hpp"

namespace crumple::testing {

// Simulates samples/SAMPLE into dir/SAMPLE (up to frame `last` when >= 0);
// returns its cache's path.
inline std::string simulateSample(const std::string& sample, const TempDir& dir, int last = -1,
                                  const std::function<void(io::SceneSpec&)>& edit = {}) {
  io::SceneSpec scene = io::loadScene(io::resolveScenePath(sourcePath("samples/" + sample)));
  if (edit) edit(scene);
  pipeline::ShotOptions options;
  options.outDir = (dir / sample).string();
  options.render = false;
  options.log = nullptr;
  options.interactive = 0;
  if (last >= 0) options.frames = pipeline::FrameRange{scene.frameStart, last};
  return pipeline::runShot(scene, options).cachePath;
}

}  // namespace crumple::testing
