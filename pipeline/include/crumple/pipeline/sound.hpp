#pragma once
// A shot's soundtrack from its cache (`crumple sound`, and the end
// of `crumple run` for a scene with [sound]): the events the simulation
// stored (SNDS / SEVT blocks) synthesised with the sound database, heard
// from the camera (or the scene's listener) over the scene's table, written
// as a WAV with its spectrogram PNG beside it. Needs nothing but the cache
// (and the database), so a farm can make it on any machine.
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "crumple/cache/pcache_sound.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/sound/events.hpp"

namespace crumple::pipeline {

struct SoundOptions {
  std::string out;                   // default: sound.wav beside the cache
  std::optional<int> sampleRate;     // default: the scene's [sound] sample_rate (48000)
  std::optional<int> channels;       // default: the scene's (2)
  std::optional<bool> floatSamples;  // default: the scene's (24-bit PCM)
  std::string database;              // default: the scene's, else assets/sound/default
  std::optional<double> gainDb;      // a fixed gain; default: the peak normalised to -1 dBFS
  bool spectrogram = true;           // the PNG beside the WAV (same name, .png)
  std::FILE* log = stderr;           // progress and notes; nullptr: quiet
  int interactive = -1;
  // Hold the WAV's folder's lock (OutputLock) while writing; false for a
  // caller that holds it already (`crumple run`).
  bool lockFolder = true;
};

struct SoundReport {
  std::string wavPath;
  std::string spectrogramPath;  // empty without one
  std::string databasePath;
  int sampleRate = 0;
  int channels = 0;
  std::int64_t samples = 0;
  double seconds = 0.0;
  int frames = 0;
  // Events in the cache, and their resonators by kind.
  long crumplingEvents = 0, frictionEvents = 0, tearingEvents = 0;
  long clacResonators = 0, flapResonators = 0;  // crumpling: constrained / free
  long constrainedFriction = 0, freeFriction = 0;
  double gainDb = 0.0;  // applied to the mix
  double peak = 0.0;    // after the gain (full scale 1)
  std::int64_t clipped = 0;
  double synthesisMs = 0.0;        // the mix, without reading the cache or writing files
  std::vector<std::string> notes;  // e.g. a cache recovered without its footer
};

// The default database folder: $CRUMPLE_ASSETS/sound/default, else the
// source tree's assets/sound/default.
std::string defaultSoundDatabase();

// Throws InputError for a cache without events, a missing or malformed
// database, a bad option, a WAV folder another crumple is writing into; the
// WAV and PNG are written atomically.
SoundReport makeSound(const std::string& cachePath, const SoundOptions& options);

// `crumple sound --events`: one line per event (frame, time, kind,
// amplitude, resonators with l_r, l_c and area).
std::string eventTimeline(const std::string& cachePath);

}  // namespace crumple::pipeline
