#include "crumple/sound/crumpling_synth.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "crumple/core/rng.hpp"

namespace crumple::sound {

// Thesis 4.3.3: nearest cell, random variant, scaled, spatialised, placed.
bool addCrumplingSound(const SoundDatabase& db, const CrumplingSound& sound,
                       const Timeline& timeline, std::uint64_t seed, std::int64_t event,
                       std::vector<float>& out) {
  if (db.sampleRate() != timeline.sampleRate())
    throw std::invalid_argument("addCrumplingSound: the database is at " +
                                std::to_string(db.sampleRate()) + " Hz, the soundtrack at " +
                                std::to_string(timeline.sampleRate()));
  if (!(sound.time >= 0.0) || !std::isfinite(sound.time))
    throw std::invalid_argument("addCrumplingSound: a negative or non-finite time");
  if (!(sound.amplitude >= 0.0) || !std::isfinite(sound.amplitude))
    throw std::invalid_argument("addCrumplingSound: a negative or non-finite amplitude");
  const SoundCell* cell = db.crumplingCell(sound.ruling, sound.border);
  if (cell == nullptr) return false;
  const CounterRng rng(seed, event, RngPurpose::SoundVariant);
  const auto& clip = cell->clips[static_cast<std::size_t>(rng.bits(0) % cell->clips.size())];
  DipoleResponse scaled = sound.response;
  scaled.direct.gain *= sound.amplitude;
  if (scaled.image) scaled.image->gain *= sound.amplitude;
  addClip(clip, scaled, timeline.sampleRate(), timeline.sampleAt(sound.time), out);
  return true;
}

}  // namespace crumple::sound
