#pragma once
// Helpers the shot's files share (pipeline-internal).
#include <string>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/io/animation.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/pipeline/shot.hpp"

namespace crumple::pipeline::detail {

// Creates the folder and checks that a file can be written in it (InputError).
void prepareOutputDir(const std::string& dir, const std::string& what);

// The camera at time t: the scene's [camera] node in the animation file,
// else its look-at pose. Throws InputError for a node without a camera.
cache::CameraRecord cameraAt(const io::SceneSpec& scene, const io::AnimationScene* animation,
                             double t);

// After the frames: the contact sheet (DIR/contact_sheet.png) and the movie
// (DIR/preview.mp4, with DIR/sound.wav when there is one), DIR being the
// shot's folder.
void finishFrames(const std::string& framesDir, const FrameRange& range, double fps,
                  const std::string& shotDir, const RenderSettings& settings,
                  std::string& contactSheetPath, std::string& moviePath,
                  std::vector<std::string>& notes);

// Writes `text` to path.tmp and renames it onto `path`. Throws InputError.
void writeTextAtomically(const std::string& path, const std::string& text);

}  // namespace crumple::pipeline::detail
