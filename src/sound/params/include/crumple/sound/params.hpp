#pragma once
// Parameters of the sound events (thesis 4.3.2; docs/SOUND.md),
// header-only: the scene's [sound] table fills them (io), EventDetector
// runs them and checks them (std::invalid_argument for bad values).

namespace crumple::sound {

// What makes a sound event and how far its vibrations reach (EventDetector,
// events.hpp).
struct EventParams {
  double gridSpacing = 0.01;  // m: the curvature grid's step in the pattern (Fig. 4.10)
  // Grids larger than this many points get a larger step (a poster).
  int maxGridPoints = 40000;
  // The curvature change |H_t - H_{t-1}| (1/m) a grid point must exceed
  // (thesis 4.3.2's threshold against small instabilities).
  double curvatureThreshold = 3.0;
  double maxDihedral = 0.5;  // a_max (rad): a ridge stops vibrations (thesis 4.3.2)
  // A sheet border bent along its length to a radius below this (m), and
  // neither held nor touching, is a free curved border (Fig. 4.8): a
  // curved region's borders across its rulings, not its straight ends.
  double freeBorderRadius = 1.0;
  // A resonator whose free borders add up to less than this (m) has none
  // that can carry a flap: it is constrained (l_c = 0). Half the database
  // grid's first step (2.5 cm).
  double minFreeBorder = 0.0125;
  double minSlideSpeed = 0.01;  // m/s: slower contacts make no friction event
  double maxTearGap = 0.5;      // s: a tear idle longer than this had stopped

  bool operator==(const EventParams&) const = default;
};

}  // namespace crumple::sound
