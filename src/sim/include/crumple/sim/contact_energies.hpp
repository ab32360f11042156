#pragma once
// The contacts of the elastic step as energies, each with its gradient and
// Hessian per stencil (docs/CONTACTS.md): ElasticSheet's Newton solve adds
// them to the incremental potential; they are public so that tests check
// them against finite differences. A step's contacts are found at its start
// and frozen over it (the touched surface as a plane or a triangle where it
// ends the step, the normal force lagged for friction).
#include <array>

#include "crumple/core/types.hpp"
#include "crumple/sim/energies.hpp"

namespace crumple::sim {

// A free vertex against a collider or another layer of the sheet.
struct VertexContact {
  int vertex = -1;
  int collider = -1;            // ColliderSet index, -1 = the sheet itself
  Vec3 point = Vec3::Zero();    // on the touched surface, where it is at the end of the step
  Vec3 normal = Vec3::UnitY();  // unit, out of the touched surface
  Vec3 motion = Vec3::Zero();   // the touched surface's displacement over the step
  double mu = 0.0;              // Coulomb friction coefficient
  double lambda = 0.0;          // lagged normal force (N) at the start of the step
  double k = 0.0;               // penalty stiffness (N/m)
  // An edge or corner contact with another layer keeps the distance to that
  // triangle, frozen where the layer's velocity carries it, rather than to a
  // plane: a plane through an edge would stand in the way of vertices that
  // pass the triangle by.
  bool toTriangle = false;
  std::array<Vec3, 3> triangle{};

  // The penalty's gap at x (the contact distance minus the distance to the
  // plane or triangle) and the direction it pushes along.
  double gap(const Vec3& x, double distance, Vec3* direction) const;
  // The penalty k/2 gap^2 where gap > 0: returns false (and writes nothing)
  // elsewhere. Gradient -k gap d; Hessian k d d^T (exact for a plane; for a
  // triangle the curvature term of the distance is left out, Gauss-Newton:
  // it would make the block indefinite).
  bool penalty(const Vec3& x, double distance, double& energy, Vec3* gradient, Mat3* hessian) const;
  // Lagged Coulomb friction (Li et al. 2020, "Incremental Potential Contact",
  // Sec. 5): the tangential displacement over the step u = T ((x - xStart) -
  // motion), T = I - n n^T, costs mu lambda f0(|u|), f0(y) = y beyond eps and
  // -y^3 / (3 eps^2) + y^2 / eps + eps / 3 below it (static friction as a
  // stiff, capped spring). Gradient and Hessian when asked (gradient needed
  // for the Hessian).
  double friction(const Vec3& x, const Vec3& xStart, double eps, Vec3* gradient,
                  Mat3* hessian) const;
};

// A collider probe (a ball's centre, a box's corner) near the inside of a
// triangle: the triangle's point at barycentric w keeps radius + distance
// from it along the normal frozen at the start of the step (vertex contacts
// alone let a ball through a coarse mesh).
struct FaceContact {
  int triangle = -1;
  int collider = -1;
  std::array<double, 3> w{};
  Vec3 probe = Vec3::Zero();  // where the probe ends the step
  double radius = 0.0;
  Vec3 normal = Vec3::UnitY();  // unit, from the probe toward the sheet
  double k = 0.0;

  // radius + distance - n . (w0 x0 + w1 x1 + w2 x2 - probe).
  double gap(const Vec3& x0, const Vec3& x1, const Vec3& x2, double distance) const;
  // The penalty k/2 gap^2 where gap > 0 (false, nothing written, elsewhere),
  // over (x0, x1, x2): gradient -k gap (w (x) n), Hessian k (w (x) n)(w (x) n)^T
  // (exact: the gap is linear).
  bool penalty(const Vec3& x0, const Vec3& x1, const Vec3& x2, double distance, double& energy,
               Vec9* gradient, Mat9* hessian) const;
};

}  // namespace crumple::sim
