#pragma once
// Private to io: what assimp 5.2 drops of an FBX file's timing. Its importer
// makes every key time of a take (animation stack) relative to the take's
// LocalStart, or to the take's first key when it has neither LocalStart nor
// LocalStop (FBXConverter::ConvertAnimationStack), so a take that starts at
// Blender's default frame 1 comes in a frame early. This reads, from the
// file's own records, each take's name, LocalStart, LocalStop and earliest
// key, so that the keys can be put back at the times the DCC showed. Only
// the node records on the way are decoded (Objects > AnimationStack >
// Properties70 > P, Objects > AnimationCurve > KeyTime, Connections > C),
// in the binary form (FBX 7.x node records, Autodesk's "FBX binary file
// format" as documented by Blender's exporter, io_scene_fbx/encode_bin.py)
// and the ASCII one.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace crumple::io::detail {

// FBX time (KTime) ticks per second.
inline constexpr double kFbxTicksPerSecond = 46186158000.0;

// One take of an FBX file.
struct FbxTake {
  std::string name;  // the stack's name without its class ("Scene", not "AnimStack::Scene")
  std::int64_t localStart = 0, localStop = 0;  // KTime; 0 when absent
  std::optional<std::int64_t> firstKey;        // the earliest key of its curves, KTime
};

// The takes of the FBX file at `path`, in file order. Throws InputError
// naming the file and the byte offset (binary) or line (ASCII) when a
// record on the way is malformed.
std::vector<FbxTake> readFbxTakes(const std::string& path);

// The time assimp 5.2 subtracted from every key of the take (s): its
// LocalStart when LocalStart or LocalStop is set, else its first key.
double assimpKeyShift(const FbxTake& take);

}  // namespace crumple::io::detail
