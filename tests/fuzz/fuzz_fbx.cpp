// libFuzzer target: handle import from FBX (binary or ASCII).
#include "fuzz_animation.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return crumple::fuzz::fuzzAnimation(data, size, ".fbx");
}
