#pragma once
// Parameters of tearing (thesis 3.3; docs/TEARING.md), header-only: the
// scene's [tear] table fills them (io), tear::Tearing runs them and checks
// them (std::invalid_argument for bad values).
#include <cstdint>
#include <numbers>

#include "crumple/core/types.hpp"

namespace crumple::tear {

// The fibers' resistance T_fibers(u, v) (FiberTexture, fiber_texture.hpp).
struct FiberTextureParams {
  double texelSize = 2.5e-4;    // m per texel: the resolution of the tears' detail
  double featureSize = 2.0e-3;  // m: the largest noise wavelength (first octave)
  int octaves = 4;              // each halves the wavelength
  double persistence = 0.5;     // amplitude ratio between octaves
  // >= 1: noise features this many times longer along fiberDirection than
  // across it (1 = isotropic).
  double anisotropy = 1.0;
  Vec2 fiberDirection = Vec2::UnitX();  // pattern direction of the fibers
  std::uint64_t seed = 1;

  bool operator==(const FiberTextureParams&) const = default;
};

// The detailed path between two tips (detailPath, detail_path.hpp). The
// thesis gives no defaults for p and G_t's width. The greedy walk is
// bimodal: it either hugs the segment (an 8-neighbour staircase, 1.10-1.15
// times the straight length) or wanders into the fibers' noise. With the
// default fiber texture, p = 0.5 and a 0.5 mm width give 1.63-2.63 times
// the straight length over seeds 1-4 (2 cm segments in 8 directions);
// p = 0.6 gives 1.14-1.92, p = 0.5 with 0.35 mm 1.12-1.14.
struct DetailPathParams {
  double blend = 0.5;           // p in eq. (3.2): 0 = fibers only, 1 = straight
  double stressWidth = 0.5e-3;  // m: the Gaussian G_t's standard deviation

  bool operator==(const DetailPathParams&) const = default;
};

// The Griffith test of the candidates (testCandidates, tear_step.hpp).
struct TearParams {
  // C: the paper's general resistance (thesis 3.3.2: 0.005), in the units
  // of E_r, i.e. of the forces given. The pipeline gives the forces in units
  // of the paper's stretch stiffness times the mesh's mean edge length
  // (k_s h, the force of unit strain over one edge), so E_r is a
  // dimensionless, strain-like number independent of the mesh resolution
  // and C = 0.005 tears where the pull at a point reaches the force of half
  // a percent of strain (office paper breaks at 1.5-3 %).
  double resistance = 0.005;
  double tipDamage = 0.5;       // D in [0, 1]: d_p at a tear's tip (1 elsewhere)
  double speed = 1.0;           // V (m per unit of E_r): the tip advances V E_r per step
  double minInwardAngle = 0.1;  // rad: inward corners sharper than pi + this

  bool operator==(const TearParams&) const = default;
};

// A shot's tearing stage (Tearing, tearing.hpp): all of the above and the
// advances' limits.
struct TearingParams {
  TearParams griffith;  // C, D, V, the inward-corner angle
  FiberTextureParams
      fibers;  // T_fibers; texelSize is the detail's resolution (seed is set by Tearing)
  DetailPathParams detail;  // p and G_t's width
  // The tip's advance V E_r is held between these multiples of the mesh's
  // mean edge length: the mesh cannot show a shorter advance without sliver
  // triangles (the detail path shows the fine shape), and a longer one per
  // frame would cut across forces the elastic step has not seen.
  double minAdvance = 0.5;
  double maxAdvance = 2.0;
  double snap = 0.2;            // CutOptions::snap
  int maxNewTearsPerFrame = 1;  // the strongest candidates (E_r / E_f) start first
  // eps_a (thesis 3.3.3, Fig. 3.20; rad): where a tear turns by more than
  // this at a tip it leaves behind, that point stays a candidate (its lip's
  // inward corner: the tear may branch there); elsewhere a tear's lips are
  // not candidates.
  double branchAngle = 0.1;
  // A new tear whose direction makes less than this angle (rad) with the
  // outline at its start does not start (0: any). The crumpling model's
  // coarse S_G cannot mesh the thin strip such a tear leaves along the
  // outline (its elastic step fails on the sliver triangles).
  double minStartAngle = 0.0;
  // A tip does not advance in a direction that turns by more than this
  // (rad) from its tear's last advance (pi: any). The crumpling model's
  // slit cannot turn back on itself.
  double maxTurn = std::numbers::pi;

  bool operator==(const TearingParams&) const = default;
};

}  // namespace crumple::tear
