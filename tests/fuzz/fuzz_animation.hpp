#pragma once
// Shared body of the animation fuzz targets (fuzz_gltf, fuzz_fbx,
// fuzz_collada): import the input through io::AnimationScene::load (assimp)
// and query every node the way the pipeline does. Any input must either load
// or throw crumple::InputError; everything else is a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "crumple/core/error.hpp"
#include "crumple/io/animation.hpp"
#include "fuzz_input.hpp"

namespace crumple::fuzz {

inline int fuzzAnimation(const std::uint8_t* data, std::size_t size, const std::string& suffix) {
  const std::string& path = writeScratch(suffix, data, size);
  try {
    const io::AnimationScene scene = io::AnimationScene::load(path);
    const double t0 = scene.startTime();
    const double t1 = scene.endTime();
    (void)scene.fileToWorld();
    (void)scene.camera("", t0);
    for (const std::string& node : scene.nodeNames()) {
      for (const double t : {t0 - 1.0, t0, 0.5 * (t0 + t1), t1, t1 + 1.0}) {
        (void)scene.worldPose(node, t);
        (void)scene.camera(node, t);
      }
      (void)scene.localKeys(node);
      (void)scene.mesh(node);
    }
  } catch (const InputError&) {
    // Rejected input: the intended behaviour.
  }
  return 0;
}

}  // namespace crumple::fuzz
