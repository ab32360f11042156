#pragma once
// Arbitrary output variables (AOVs): per-pixel data of the surfaces the
// camera rays hit first, beside the beauty image, for a compositor
// (docs/RENDERING.md "AOVs"). The path tracer computes them from the same
// camera rays as the beauty (no extra rays); channels are named as Nuke and
// Blender's compositor read a multi-layer OpenEXR file: "layer.channel" with
// a one-letter channel (Blender's reader takes no other), and the single "Z";
// the ids take Blender's own object-index pass name, IndexOB.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "crumple/core/image.hpp"

namespace crumple::render {

// The AOVs, in the order their channels are written.
enum class Aov : std::uint8_t {
  Depth,     // Z: the nearest first hit's distance along the camera's view axis (m)
  Normal,    // N.X, N.Y, N.Z: world shading normal facing the camera, mean over the hits
  Albedo,    // albedo.R, .G, .B: the first hit's albedo, premultiplied by coverage
  Position,  // P.X, P.Y, P.Z: world position, mean over the hits (m)
  Region,    // region.R, .G, .B: coverage by flat, curved, singular-neighbourhood paper
  HandleId,  // IndexHandle.X: the handle (1-based) nearest in the pattern to the sheet seen
  ObjectId,  // IndexOB.X: 1 the sheet, 2 the ground, 3 + k the scene's prop k
};

inline constexpr int kAovCount = 7;

// The command-line name of an AOV ("depth", "normal", "albedo", "position",
// "region", "handle-id", "object-id").
std::string_view aovName(Aov aov);

// The AOV of a command-line name; nullopt when it names none.
std::optional<Aov> parseAov(std::string_view name);

// The AOVs of a comma-separated list ("depth,normal"), each once, in Aov
// order; throws std::invalid_argument naming an unknown or repeated entry.
std::vector<Aov> parseAovList(std::string_view list);

// The depth written where no camera ray hit anything (Blender's background
// depth).
inline constexpr float kAovFarDepth = 1e10f;

// The AOVs of one frame: their channels in Aov order (aovChannelNames).
using AovImage = ImageChannels;

// The channel names of an AOV, in order.
std::vector<std::string> aovChannelNames(Aov aov);

}  // namespace crumple::render
