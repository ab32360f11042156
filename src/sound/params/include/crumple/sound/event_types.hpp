#pragma once
// A sound-source event and the resonators it sets vibrating (thesis 4.3.2;
// docs/SOUND.md): plain data, with no code, so that the cache's SEVT block
// (cache/pcache_sound.hpp) stores the very events the sound module detects
// and mixes. The detection is in events.hpp.
#include <cstdint>
#include <vector>

#include "crumple/core/types.hpp"

namespace crumple::sound {

// A resonator (thesis 4.3.2-4.3.4): its size parameters, and the disk that
// radiates its sound (a dipole at its centre, along its mean normal, of its
// area).
struct Resonator {
  double ruling = 0.0;  // l_r (m): mean ruling length
  double border = 0.0;  // l_c (m): free curved border length; 0: constrained
  double area = 0.0;    // m^2
  Vec3 centre = Vec3::Zero();
  Vec3 normal = Vec3::UnitY();
  double radius = 0.0;  // m: sqrt(area / pi)
  bool constrained() const { return border == 0.0; }
  bool operator==(const Resonator&) const = default;
};

enum class EventKind : std::uint8_t { Crumpling = 0, Friction = 1, Tearing = 2 };

struct SoundEvent {
  EventKind kind = EventKind::Crumpling;
  // Crumpling: the sum of the curvature changes, each times its grid cell's
  // area (m; grid-independent). Friction: the mean sliding speed (m/s).
  // Tearing: the tip's speed (m/s) over `duration`.
  double amplitude = 0.0;
  // Tearing: the time (s) the advance took, ending at the frame: since the
  // tear's previous advance (the simulation moves a tip in jumps while the
  // tear runs on between them), at most maxTearGap; one frame for a new
  // tear.
  double duration = 0.0;
  Vec3 position = Vec3::Zero();       // where it happened
  Vec3 normal = Vec3::UnitY();        // the sheet's normal there (tearing)
  int tear = -1;                      // tearing: the tear
  std::vector<Resonator> resonators;  // crumpling and friction
  bool operator==(const SoundEvent&) const = default;
};

}  // namespace crumple::sound
