#pragma once
// User parameters of the hybrid crumpling model (paper Table VI; thesis
// 2.3.3, 2.4.1), header-only: the scene's [model] table fills them (io),
// HybridSheet runs them. Lengths are in metres, angles in radians.
#include <numbers>
#include <string>

namespace crumple::paper {

struct CrumpleParams {
  // Boundary sampling density of S_P and of curved-region rulings (paper
  // Table VI: 1.2 samples/cm), in samples per metre.
  double rhoBound = 120.0;
  // Interior sampling density of flat regions in S_P, samples per m^2.
  // Table VI prints "6 samples/cm^2", which would put ~600 interior vertices
  // on the 10 cm validation sheet, while Table V's meshes average 87-156
  // triangles. We read the 6 as samples per row across L_paper = 10 cm,
  // i.e. an isotropic spacing of 10/6 cm and (6/10 cm)^2 = 0.36 /cm^2: a flat
  // 10 cm sheet then has 48 boundary and ~25-36 interior samples, ~118
  // triangles (Table V, Fig. 1). See docs/CRUMPLING.md "S_P size".
  double rhoInt = 3600.0;
  double theta0 = 0.01;        // coplanarity threshold (rad)
  double thetaLow = 0.001;     // junction hysteresis, theta0 / 10
  double thetaHigh = 0.01;     // junction hysteresis, theta0
  double epsBlaschke = 0.005;  // cone-fit tolerance as a fraction of L_paper
  double epsC = 0.001;         // compression threshold (0.1 %)
  // A ruling of a curved region gets a d-cone (treatCurvedCompression, our
  // extension) when compressed by more than this times epsC: rulings are
  // straight in S_G but S_P bends smoothly across them, so a twisting strip
  // shortens them slightly without any crumpling (moebius: 0.11 %).
  double curvedCompressionFactor = 5.0;
  double sigma = 0.001;                       // singular-vertex position spread (0.1 cm)
  double thetaRest = std::numbers::pi / 8.0;  // fiber damage rest angle (thesis eq. 2.1)
  double damage = 10.0;                       // fiber damage D (thesis eq. 2.2)
  int isometryIterations = 200;               // Phase I iteration cap (paper Sec. 6.3)
  int isometryRounds = 1;  // Phase I + II passes per step (IsometryOptions::rounds)
  // Gauss-Seidel edge-length sweeps after Phase II and their early-exit
  // tolerance (IsometryOptions::lengthSweeps, isometry.hpp deviation 7): the
  // model's accuracy knob (docs/BENCH.md), `[model] isometry_length_sweeps`.
  int isometryLengthSweeps = 300;
  double isometryLengthTolerance = 1e-6;
  // Whether the isometry also holds the handles' tangent-plane pins; by
  // default only the handle vertices (paper Sec. 6.3 "handles fixed") and
  // the tangent plane is imposed in the elastic step (docs/CRUMPLING.md).
  bool isometryHoldsTangentPins = false;
  // Membrane stiffness of the coarse FEM on S_P as a fraction of the paper's
  // (sim::SimParams::membraneScale): "stiffness only needs to be of medium
  // range" (paper Sec. 1), lengths are restored by the isometry step.
  double membraneScale = 0.01;
  double minVertexMassFraction = 0.05;  // sim::SimParams::minVertexMassFraction for S_P
  // Hinges of S_P whose two triangles are slivers, (A1 + A2) / |e|^2 below
  // this (0.87 for two equilateral triangles), are softened by that ratio:
  // the discrete hinge stiffness grows like |e|^2 / (A1 + A2) and its
  // Hessian like 1 / height^3, which stalls Newton on the long thin cells
  // that rulings make (see docs/CRUMPLING.md "Sliver hinges").
  double sliverHingeRatio = 0.1;
  // Newton tolerance of the coarse FEM on S_P (sim::SimParams::newtonTolerance,
  // a fraction of the mean edge length, here ~12 um): the isometry step moves
  // S_P's vertices by ~1e-2 of an edge every step, so resolving the elastic
  // step to the plain model's 1e-7 buys nothing and stalls Newton on
  // compressed cells (with 1e-4 moebius grew 7-13 singular vertices and
  // crumple failed in 2 of 3 seeds; with 1e-3 none and none).
  double newtonTolerance = 1e-3;
  int newtonIterations = 60;  // sim::SimParams::maxNewtonIterations for S_P (plain model: 30)
  // Steps a region waits after it was cut before its compression is treated
  // again: cutting a compressed region leaves equally compressed pieces
  // until the elastic steps have bent S_P along the new structure (Appendix
  // B: "let the physical simulation further deform this region").
  int remeshCooldown = 3;
  // At most this many new singular vertices per frame, over its animation
  // steps (the most compressed regions first): singular points appear
  // "progressively" (paper Sec. 7.3).
  int maxSingularPerFrame = 2;
  // Paper stays paper: after every animation step S_P's max relative edge
  // strain is at most this, the handles lagging when no configuration with
  // them on their targets meets it (strain_limit.hpp). 0 turns it off
  // (docs/CRUMPLING.md, "Strain limit").
  double maxEdgeStrain = 0.02;
  int strainLimitIterations = 30;  // Levenberg-Marquardt steps per projection
  // A handle the bound left behind its node closes that lag at most this
  // much faster than its node moves (m/s), on a straight path from where it
  // is: a finger that slipped comes back, it does not jump there in one step
  // (docs/CRUMPLING.md "Popping"). 0: the whole lag at once. Only with the
  // strain limit on (maxEdgeStrain > 0), which is what makes handles lag.
  double lagCatchUpSpeed = 0.02;
#ifdef NDEBUG
  bool checkInvariants = false;  // validate S_G and S_P after every geometric step
#else
  bool checkInvariants = true;
#endif

  bool operator==(const CrumpleParams&) const = default;
};

}  // namespace crumple::paper
