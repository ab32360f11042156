#pragma once
// The files besides the scene file that shape a shot, each with a 64-bit
// hash of its bytes and its size: what a checkpoint records so that
// `--resume` refuses a shot whose inputs changed since it was written
// (docs/CHECKPOINT.md). Internal to the pipeline.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "crumple/io/scene.hpp"

namespace crumple::pipeline {

// FNV-1a, 64 bits; `hash` continues an earlier one over more bytes.
inline constexpr std::uint64_t kFnv1aStart = 0xcbf29ce484222325ull;
std::uint64_t fnv1a64(const void* data, std::size_t size, std::uint64_t hash = kFnv1aStart);

struct ShotInput {
  std::string what;  // "the animation file", "the paper preset", ...: for the messages
  std::string path;
  std::uint64_t size = 0;  // bytes
  std::uint64_t hash = 0;  // fnv1a64 of the bytes
};

// The animation file and, for a .gltf, the files its "uri"s name (buffers,
// images; not data: URIs), the paper preset file, the paper texture; in
// that order, each one that the scene has. Throws InputError naming a file
// that cannot be read.
std::vector<ShotInput> shotInputs(const io::SceneSpec& scene);

}  // namespace crumple::pipeline
