#pragma once
// A shot's soundtrack from its events (thesis Algorithm 4 and 4.3.4):
// every crumpling resonator's clip at its frame's
// sample, the friction resonators' spectra summed per frame and sounded as
// noise, every tear's crackle following its tip's speed; each source a
// dipole, with its image in the table, heard from the listener (the
// camera), in mono or stereo.
#include <cstdint>
#include <optional>
#include <vector>

#include "crumple/core/types.hpp"
#include "crumple/sound/database.hpp"
#include "crumple/sound/events.hpp"
#include "crumple/sound/spatialize.hpp"
#include "crumple/sound/tearing_noise.hpp"
#include "crumple/sound/wav.hpp"

namespace crumple::sound {

// One frame's events and where they are heard from.
struct FrameEvents {
  std::vector<SoundEvent> events;
  Vec3 listener = Vec3::Zero();  // the camera's position, or the scene's listener
  Vec3 right = Vec3::UnitX();    // the listener's right (stereo: the ears along it)
};

struct SoundtrackSettings {
  int channels = 2;                      // 1: mono at the listener; 2: left and right ears
  double earSpacing = 0.18;              // m between the two ears
  std::optional<ReflectingPlane> table;  // the image sources' plane (4.3.4)
  // Levels. A source's gain is its dipole's (a^3 cos(theta) / R) over that
  // of a 5 cm disk facing the listener 1 m away (so 1 there), times:
  double referenceRadius = 0.05;     // m
  double crumplingReference = 0.01;  // m: the event amplitude that plays a clip as stored
  double frictionReference = 0.1;    // m/s: the slide speed that plays a spectrum as stored
  double crumplingGain = 1.0;
  double frictionGain = 1.0;
  TearingNoiseParams tearing;   // its gain is the crackle's at its reference speed
  double tearingRadius = 0.02;  // m: the disk a tip radiates as
  std::uint64_t seed = 1;
};

// What went into it.
struct SoundtrackStats {
  long crumplingClips = 0;  // resonator clips placed
  long frictionBlocks = 0;  // noise blocks synthesised (per channel)
  long tearingSamples = 0;  // samples of tearing noise (per channel)
  long silentSources = 0;   // sources at the listener (less than 1 cm away): not heard
};

// frames[0] is the timeline's first frame (t = 0), frames[f] sounds at
// timeline.frameStart(f); frames beyond the timeline are ignored. Throws
// std::invalid_argument when the database's rate is not the timeline's, or
// for a channel count other than 1 or 2.
Audio renderSoundtrack(const SoundDatabase& db, const Timeline& timeline,
                       const std::vector<FrameEvents>& frames, const SoundtrackSettings& settings,
                       SoundtrackStats* stats = nullptr);

// The largest |sample| over all channels.
double peakLevel(const Audio& audio);

}  // namespace crumple::sound
