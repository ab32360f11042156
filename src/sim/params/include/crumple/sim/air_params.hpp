#pragma once
// Parameters of the air (docs/AIR.md), header-only: the scene's [air] table
// fills them (io), the elastic step runs them (sim/air.hpp). A scene without
// [air] has none, and its steps do no air work at all.
#include <cstdint>
#include <numbers>
#include <vector>

#include "crumple/core/types.hpp"

namespace crumple::sim {

// The mean wind at `time` (s): keys are interpolated linearly in time and
// held constant before the first and after the last.
struct WindKey {
  double time = 0.0;
  Vec3 velocity = Vec3::Zero();  // m/s
  bool operator==(const WindKey&) const = default;
};

// Gusts: a divergence-free random field of `modes` Fourier modes (Kraichnan
// 1970's random-mode synthesis) with wavenumbers drawn from a Kolmogorov
// k^(-5/3) spectrum between 2 pi / lengthScale and 8 times that, carried by
// the mean wind (Taylor's frozen turbulence) and decorrelating over
// timeScale. Deterministic: the modes are drawn from the counter-based RNG
// keyed by `seed`. speed = 0: no gusts.
struct GustParams {
  double speed = 0.0;        // m/s, root-mean-square of the gust velocity
  double lengthScale = 0.5;  // m, the largest eddy
  double timeScale = 1.0;    // s
  int modes = 32;
  std::uint64_t seed = 0;  // the shot's seed ([scene] seed or --seed; the shot sets it)
  bool operator==(const GustParams&) const = default;
};

// The quasi-steady model of a thin plate in air, applied per triangle
// (Andersen, Pesavento & Wang 2005, J. Fluid Mech. 541, 65-90, eqs. (5.1)-(5.5),
// generalised to 3D facets as Wejchert & Haumann 1991 do). Defaults are
// measured values; docs/AIR.md gives each source.
struct AirParams {
  double density = 1.204;  // kg/m^3, dry air at 20 C and 1 atm
  std::vector<WindKey> wind;
  GustParams gusts;
  // Drag along the relative velocity: C_D(alpha) = dragTangential cos^2 alpha
  // + dragNormal sin^2 alpha, alpha the angle of attack (Andersen et al.'s
  // A - B cos 2 alpha). dragNormal: a square flat plate broadside (Hoerner
  // 1965, Fluid-Dynamic Drag); dragTangential: Andersen et al.'s ratio
  // C_D(0) / C_D(pi/2) = 0.4 / 2.4 applied to it.
  double dragNormal = 1.17;
  double dragTangential = 0.195;
  // Translational circulation (lift of a plate at an angle of attack):
  // Andersen et al.'s C_T.
  double translationalLift = 1.2;
  // Rotational circulation (lift of a turning plate): Andersen et al.'s C_R.
  double rotationalLift = std::numbers::pi;
  // Added mass per unit area of motion normal to the sheet: density *
  // addedMass * chord, pi/4 for a 2D plate (potential flow, m22 = rho pi a^2).
  double addedMass = std::numbers::pi / 4.0;
  // Faces whose upwind ray meets another part of the sheet within a chord
  // feel the air in proportion to that distance (docs/AIR.md "Sheltering").
  bool shelter = true;

  bool operator==(const AirParams&) const = default;
};

}  // namespace crumple::sim
