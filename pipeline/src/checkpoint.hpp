#pragma once
// Checkpoint files: a shot's whole simulation state after a frame,
// DIR/checkpoint.bin, written atomically (PATH.tmp, fsync, rename), checked
// by a CRC32 and by the shot it belongs to (scene text, the content of every
// other file that shapes it, seed, frame range). Internal to the pipeline;
// the layout is in docs/CHECKPOINT.md.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "crumple/core/state_io.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/pipeline/shot.hpp"
#include "shot_inputs.hpp"

namespace crumple::pipeline {

inline constexpr const char* kCheckpointFile = "checkpoint.bin";

struct Checkpoint {
  int frame = 0;                 // the last frame the state has simulated
  std::size_t cachedFrames = 0;  // the cache's frames that go with it
  std::shared_ptr<const std::vector<std::uint8_t>> bytes;
  std::unique_ptr<StateReader> state;  // after the head: the stages' sections follow
};

// The head: which shot (the scene text, its inputs as shotInputs gave them
// when the shot started, seed, frame range), which frame, how many cached
// frames.
void writeCheckpointHead(StateWriter& w, const io::SceneSpec& scene,
                         const std::vector<ShotInput>& inputs, std::uint64_t seed, int lastFrame,
                         int frame, std::size_t cachedFrames);
// Writes w's bytes and their CRC to `path` atomically. Throws InputError.
void writeCheckpointFile(const std::string& path, const StateWriter& w);
// Reads and checks a checkpoint for this shot. Throws InputError when there
// is none, when it belongs to another shot (scene, seed or frame range),
// when one of its inputs changed (naming it), or when it is damaged (CRC,
// truncated).
Checkpoint readCheckpoint(const std::string& path, const io::SceneSpec& scene,
                          const std::vector<ShotInput>& inputs, std::uint64_t seed, int lastFrame);

// The report's running counters and records (everything summary.json says
// about the frames simulated so far), so that a resumed run's summary is the
// uninterrupted run's.
void saveReport(StateWriter& w, const ShotReport& r);
// `handles`: the scene's handle count, which the records' handle indices
// are checked against.
void restoreReport(StateReader& in, ShotReport& r, std::size_t handles);
// Its tearing part: every advance (the hand-over replays them, the sound
// events read the frame's), the tears' frames and counts, and the notes.
void saveTearingReport(StateWriter& w, const ShotReport& r);
void restoreTearingReport(StateReader& in, ShotReport& r);

// A cache sub-block carried from frame to frame (the baked tear textures).
void saveBlock(StateWriter& w, const cache::ExtensionBlock& b);
cache::ExtensionBlock restoreBlock(StateReader& in);

}  // namespace crumple::pipeline
