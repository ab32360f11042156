#pragma once
// Air on the sheet (docs/AIR.md): the quasi-steady aerodynamics of a thin
// plate (Andersen, Pesavento & Wang 2005, J. Fluid Mech. 541, 65-90,
// eqs. (5.1)-(5.5)) applied to every triangle relative to the local wind, as
// Wejchert & Haumann 1991 apply per-facet forces. Each triangle feels
//  - drag along its relative velocity u with C_D(alpha) (implicit: a convex
//    potential in u with the angle of attack frozen at the step's start),
//  - the added mass of the air it pushes normal to itself (implicit: an
//    inertia term with the normal frozen at the step's start), and the
//    forces that mass exerts as the triangle turns (explicit, from the
//    Lagrangian of the air's kinetic energy: the Munk moment),
//  - lift from the translational and the rotational circulation (explicit),
//  - in proportion to how exposed it is: a face whose upwind ray meets the
//    sheet within a chord is sheltered.
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "crumple/core/types.hpp"
#include "crumple/sim/air_params.hpp"
#include "crumple/sim/energies.hpp"

namespace crumple::sim {

class ColliderSet;

// What is wrong with the parameters (a negative coefficient, a non-finite
// wind key, ...), or empty when nothing is.
std::string airParamsProblem(const AirParams& params);

// The wind velocity at any point and time (m/s): the mean wind's keys plus
// the gusts (AirParams, GustParams). A pure function of (params, x, t).
class WindField {
 public:
  explicit WindField(const AirParams& params);
  Vec3 mean(double t) const;
  Vec3 at(const Vec3& x, double t) const;
  // The wind at every point at t0 and at t1 (a step's start and end), as
  // at() gives them to rounding: the mean wind and its travel once, and one
  // sine and cosine per mode and point (a mode's phase at t0 is its phase at
  // t1 shifted by the same angle everywhere).
  void sampleStep(const std::vector<Vec3>& points, double t0, double t1, std::vector<Vec3>& atStart,
                  std::vector<Vec3>& atEnd) const;
  // How far the mean wind has carried the air from time 0 to t (m).
  Vec3 travel(double t) const;

 private:
  struct Mode {
    Vec3 wavevector;   // rad/m
    Vec3 amplitude;    // m/s, perpendicular to the wavevector
    double frequency;  // rad/s
    double phase;      // rad
  };
  std::vector<WindKey> keys_;
  std::vector<Mode> modes_;
};

// One triangle's air over a step of length h, frozen at the step's start.
struct AirTriangleFrame {
  Vec3 normal = Vec3::UnitZ();        // unit normal at x_n
  Vec3 centroidStart = Vec3::Zero();  // centroid at x_n
  Vec3 inertiaTarget = Vec3::Zero();  // centroid at x_n + h v_n
  Vec3 wind = Vec3::Zero();           // at the centroid, end of the step
  double drag = 0.0;                  // 1/2 rho A C_D(alpha_n) times the exposure (kg/m)
  double addedMass = 0.0;             // rho addedMass chord A times the openness (kg)
};

// The implicit part of one triangle's air at positions (x0, x1, x2) over a
// step of length h (J): h drag/3 |u|^3 with u = (centroid - centroidStart)/h
// - wind (its gradient is the drag force -drag |u| u spread over the three
// vertices), plus 1/2 addedMass (normal . (centroid - inertiaTarget))^2 / h^2.
// Gradient and Hessian (positive semi-definite) with respect to the nine
// coordinates when asked, and the Hessian with respect to the centroid
// (the nine coordinates' Hessian is that block / 9 for every vertex pair).
double airTriangleEnergy(const AirTriangleFrame& frame, double h, const Vec3& x0, const Vec3& x1,
                         const Vec3& x2, Vec9* gradient = nullptr, Mat9* hessian = nullptr,
                         Mat3* centroidHessian = nullptr);

// The explicit forces on one triangle's vertices at positions x and
// velocities v (N): the circulation's lift, translational and rotational
// (eq. (5.4): from the motion of the triangle's whole piece as a rigid body,
// its centre's velocity and its spin, as Andersen et al. take the plate's),
// and the added mass's forces as the triangle turns (d/dt of the air's
// momentum through the normal, and the derivative of its kinetic energy by
// the positions: the Munk moment), plus the added mass carried along by a
// changing wind (windRate = dw/dt). exposure scales the lift as it scales
// drag, openness the added mass's forces as it scales its inertia.
struct AirExplicitInput {
  std::array<Vec3, 3> x, v;
  Vec3 wind = Vec3::Zero();
  Vec3 windRate = Vec3::Zero();
  Vec3 pieceVelocity = Vec3::Zero();  // the piece's centre of mass (m/s)
  Vec3 pieceSpin = Vec3::Zero();      // the piece's angular velocity (rad/s)
  double chord = 0.0;                 // m
  double exposure = 1.0;              // in [0, 1]
  double openness = 1.0;              // in [0, 1]
};
// `circulation`, when given, receives the circulation's lift alone (the
// forces with openness 0).
std::array<Vec3, 3> airExplicitForces(const AirParams& params, const AirExplicitInput& in,
                                      std::array<Vec3, 3>* circulation = nullptr);

// The air of one sheet for ElasticSheet: built on its triangles and pattern
// (the chord of every connected piece: twice its area over its perimeter,
// the width of a long strip and the radius of a disc).
class AirModel {
 public:
  AirModel(const AirParams& params, const std::vector<std::array<int, 3>>& triangles,
           const std::vector<Vec2>& pattern, std::size_t vertexCount);
  ~AirModel();
  AirModel(AirModel&&) noexcept;
  AirModel& operator=(AirModel&&) noexcept;

  // Freezes the step from t0 to t1 at positions x and velocities v: every
  // triangle's frame, its exposure and the explicit forces. Near a collider
  // (within a chord) the wind turns parallel to its surface, fully so at
  // the surface: air does not blow through a table (docs/AIR.md "Walls").
  void beginStep(const std::vector<Vec3>& x, const std::vector<Vec3>& v, double t0, double t1,
                 const ColliderSet* colliders = nullptr);
  // The corrector (Heun's trapezoid, docs/AIR.md "Time step"): with the
  // step solved to (x1, v1), the circulation's lift becomes the mean of its
  // values at the step's start and at (x1, v1), and so does each frame's
  // drag coefficient (its angle of attack); the caller moves the step to
  // the corrected minimiser. The added mass's forces, exposure and
  // openness stay the start's. Returns how much the forces on each vertex
  // changed at (x1, v1) (N).
  std::vector<Vec3> correctStep(const std::vector<Vec3>& x1, const std::vector<Vec3>& v1);
  const std::vector<AirTriangleFrame>& frames() const;
  // Per vertex (N), summed over its triangles in triangle order: at the
  // step's start, with the lift corrected after correctStep.
  const std::vector<Vec3>& explicitForces() const;
  // Per triangle, in [0, 1] (docs/AIR.md "Sheltering"): how much of the
  // flow reaches it (its upwind ray's free length over the chord), which
  // scales drag and lift; and how open its two sides are (the mean of its
  // rays' free lengths along +n and -n over the chord), which scales its
  // added mass: the air between two layers or inside a ball moves with it.
  const std::vector<double>& exposure() const;
  const std::vector<double>& openness() const;
  double chord(std::size_t triangle) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace crumple::sim
