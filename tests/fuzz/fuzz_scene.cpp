// libFuzzer target: the scene parser, io::parseScene (docs/SCENE.md). Any
// input must either parse or throw crumple::InputError; everything else (a
// sanitizer report, a signal, another exception, a hang) is a bug.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "crumple/core/error.hpp"
#include "crumple/io/scene.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    // checkFiles = false: the animation file named by the input need not exist.
    const crumple::io::SceneSpec scene =
        crumple::io::parseScene(text, "fuzz.toml", CRUMPLE_FUZZ_SCENE_DIR, false);
    (void)scene.frameTime(scene.frameEnd);
  } catch (const crumple::InputError&) {
    // Rejected input: the intended behaviour.
  }
  return 0;
}
