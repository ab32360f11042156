// libFuzzer target: handle import from glTF 2.0 (.gltf text, or .glb when the
// input starts with the binary container's magic "glTF").
#include <cstring>

#include "fuzz_animation.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const bool binary = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  return crumple::fuzz::fuzzAnimation(data, size, binary ? ".glb" : ".gltf");
}
