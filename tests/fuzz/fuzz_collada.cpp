// libFuzzer target: handle import from COLLADA (.dae).
#include "fuzz_animation.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return crumple::fuzz::fuzzAnimation(data, size, ".dae");
}
