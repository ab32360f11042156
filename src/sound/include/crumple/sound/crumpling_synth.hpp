#pragma once
// A crumpling event's sound (thesis 4.3.3): the clip of
// the database cell nearest its resonator's (l_r, l_c), one of the cell's
// variants drawn at random, scaled by the event's amplitude, spatialised
// (eq. 4.11) and placed at the event's exact sample.
#include <cstdint>
#include <vector>

#include "crumple/sound/database.hpp"
#include "crumple/sound/spatialize.hpp"
#include "crumple/sound/wav.hpp"

namespace crumple::sound {

struct CrumplingSound {
  double time = 0.0;        // s after the shot's first frame
  double amplitude = 0.0;   // the event's (thesis Fig. 4.10: the sum of its curvature changes)
  double ruling = 0.0;      // the resonator's l_r (m)
  double border = 0.0;      // the resonator's l_c (m); 0: constrained
  DipoleResponse response;  // dipoleResponse for the resonator and the listener
};

// Adds the event's sound into `out` at timeline.sampleAt(time): the direct
// path at that sample (the picture's time: no acoustic delay), the table's
// image after it. The variant is CounterRng(seed, event) of the cell's
// clips. Returns false, adding nothing, when no cell has clips. Throws
// std::invalid_argument when the database's rate is not the timeline's, or
// for a negative time, a negative or non-finite amplitude.
bool addCrumplingSound(const SoundDatabase& db, const CrumplingSound& sound,
                       const Timeline& timeline, std::uint64_t seed, std::int64_t event,
                       std::vector<float>& out);

}  // namespace crumple::sound
