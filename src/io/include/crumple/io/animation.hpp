#pragma once
// Keyframed node animation imported through assimp from glTF 2.0 (.gltf/.glb),
// FBX and COLLADA, normalised into crumple's world frame: Y-up, metres,
// seconds. Positions interpolate linearly, rotations by slerp; times before
// the first key or after the last clamp. Parent transforms are composed, so a
// node parented under an animated node moves with it; a node without
// animation channels is a constant track.
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "crumple/core/types.hpp"

namespace crumple::io {

// Keys of one node's local transform (relative to its parent), in seconds.
struct NodeKeys {
  std::vector<double> positionTimes;
  std::vector<Vec3> positions;
  std::vector<double> rotationTimes;
  std::vector<Quat> rotations;
  std::vector<double> scalingTimes;
  std::vector<Vec3> scalings;
};

struct CameraPose {
  Vec3 position = Vec3::Zero();
  Quat rotation = Quat::Identity();  // camera looks down its local -Z, +Y up (glTF)
  double yfov = 0.0;                 // rad, 0 = not given by the file
  double aspect = 0.0;               // width / height from the file, 0 = not given
};

// A flat mesh in the file (for a sheet pattern), in world coordinates at t = 0.
struct ImportedMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;
};

class AnimationScene {
 public:
  // Throws InputError naming the file for a missing or malformed file, or a
  // NaN/Inf key.
  static AnimationScene load(const std::string& path);
  AnimationScene(AnimationScene&&) noexcept;
  AnimationScene& operator=(AnimationScene&&) noexcept;
  ~AnimationScene();

  const std::string& file() const;
  std::vector<std::string> nodeNames() const;
  bool hasNode(const std::string& name) const;
  // World pose of a node at time t (seconds). Throws InputError (naming the
  // file and the node) for an unknown node.
  Pose worldPose(const std::string& node, double t) const;
  // The full node-to-world transform (metres, Y-up), including any scale.
  Mat4 worldMatrix(const std::string& node, double t) const;
  // The node's local keys in seconds, in the file's own units and axes (no
  // conversion); all vectors empty for a node without animation channels.
  NodeKeys localKeys(const std::string& node) const;
  // Transform from the file's world frame into crumple's (metres, Y-up):
  // identity for glTF and COLLADA (assimp bakes COLLADA's <unit> and
  // <up_axis> into the root node), unit scale and axis change for FBX.
  Mat4 fileToWorld() const;
  // Things worth telling the user that did not stop the import (ignored
  // channels, duplicate animations, missing ticks per second, ...).
  const std::vector<std::string>& warnings() const;
  // Time span covered by keys, [0, 0] for a static file.
  double startTime() const;
  double endTime() const;
  // The camera attached to `node` (or the first camera when node is empty).
  std::optional<CameraPose> camera(const std::string& node, double t) const;
  // The mesh attached to node `name` (world space at t = 0), if any.
  std::optional<ImportedMesh> mesh(const std::string& name) const;

 private:
  struct Impl;
  explicit AnimationScene(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// assimp ticks to seconds: time / ticksPerSecond, or time /
// kFallbackTicksPerSecond when the file gives no rate (ticksPerSecond <= 0;
// 25 is what assimp's own viewer assumes).
inline constexpr double kFallbackTicksPerSecond = 25.0;
double ticksToSeconds(double ticks, double ticksPerSecond);

// Sample a keyed track: linear positions / slerp rotations, clamped ends.
Vec3 samplePosition(const std::vector<double>& times, const std::vector<Vec3>& values, double t,
                    const Vec3& fallback);
Quat sampleRotation(const std::vector<double>& times, const std::vector<Quat>& values, double t,
                    const Quat& fallback);
// Scaling keys interpolate linearly, like positions.
inline Vec3 sampleScaling(const std::vector<double>& times, const std::vector<Vec3>& values,
                          double t, const Vec3& fallback) {
  return samplePosition(times, values, t, fallback);
}

}  // namespace crumple::io
