#pragma once
// Per-element elastic energies of the sheet (paper Sec. 4; thesis 2.3.1) with
// analytic gradients and Hessians. ElasticSheet uses them; they are public so
// that tests can check them against finite differences.
//
//  * Membrane: constant-strain triangle, Green strain E = 1/2 (F^T F - I),
//    plane-stress St. Venant-Kirchhoff energy
//        W = A h (lambda/2 tr(E)^2 + mu tr(E^2)),
//    lambda = E_Y nu / (1 - nu^2), mu = E_Y / (2 (1 + nu)), so that
//    (lambda + 2 mu) h = Material::stretchStiffness().
//  * Bending: discrete shells hinge energy (Grinspun et al. 2003; Bridson et
//    al. 2003), W = k (theta - theta_rest)^2 with
//        k = k_b * f * 3 |e|^2 / (A_1 + A_2)   (rest edge and areas)
//    and k_b = D / 6, D = Material::bendingStiffness(). See hingeStiffness().
#include <Eigen/Core>

#include "crumple/core/types.hpp"
#include "crumple/sim/material.hpp"

namespace crumple::sim {

using Vec9 = Eigen::Matrix<double, 9, 1>;
using Mat9 = Eigen::Matrix<double, 9, 9>;
using Vec12 = Eigen::Matrix<double, 12, 1>;
using Mat12 = Eigen::Matrix<double, 12, 12>;

// Plane-stress St. Venant-Kirchhoff moduli (Pa) and the sheet thickness (m).
struct MembraneModuli {
  double lambda = 0.0;  // E nu / (1 - nu^2)
  double mu = 0.0;      // E / (2 (1 + nu))
  double thickness = 0.0;
};
MembraneModuli membraneModuli(const Material& material);

// Rest data of a triangle from its pattern (2D) corners.
struct TriangleRest {
  Mat2 dmInverse = Mat2::Identity();  // inverse of [p1 - p0, p2 - p0]
  double area = 0.0;                  // pattern area (m^2)
};
// Throws std::invalid_argument on a degenerate pattern triangle.
TriangleRest triangleRest(const Vec2& p0, const Vec2& p1, const Vec2& p2);

// Green strain E = 1/2 (F^T F - I) of a triangle, F = [x1-x0, x2-x0] Dm^-1.
Mat2 greenStrain(const Vec3& x0, const Vec3& x1, const Vec3& x2, const TriangleRest& rest);
// Largest absolute principal value of a symmetric 2x2 strain.
double maxAbsPrincipal(const Mat2& strain);

// Membrane energy (J) of a triangle; gradient and Hessian with respect to
// (x0, x1, x2) when the pointers are non-null.
double membraneEnergy(const Vec3& x0, const Vec3& x1, const Vec3& x2, const TriangleRest& rest,
                      const MembraneModuli& moduli, Vec9* gradient = nullptr,
                      Mat9* hessian = nullptr);

// Signed dihedral angle (rad, in (-pi, pi]) of the hinge x0-x1, with wings
// x2 and x3, ordered so that triangle A = (x0, x1, x2) and triangle B =
// (x1, x0, x3) are both counter-clockwise in the pattern. theta = 0 when
// flat; theta > 0 when the hinge is convex on the side the (pattern-oriented)
// normals point to, i.e. the two normals diverge. theta = atan2(y, c) with
// c = n_A . n_B and y = (n_A x n_B) . e/|e| (unnormalised normals), so the
// analytic gradient and Hessian are exact for any fold angle.
double dihedralAngle(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3,
                     Vec12* gradient = nullptr, Mat12* hessian = nullptr);

// Stiffness k (J/rad^2) of a hinge: k_b * factor * 3 |e|^2 / (A_1 + A_2)
// with k_b = D / 6, i.e. D * factor * |e|^2 / (2 (A_1 + A_2)).
// Calibration (measured, see tests/sim): on an equilateral triangle lattice
// wrapped on a cylinder of curvature kappa, sum_e 3 |e|^2/(A1+A2) theta_e^2
// = 3 kappa^2 * area, for every cylinder direction; k_b = D / 6 therefore
// gives the continuum plate energy D/2 kappa^2 per unit area on isotropic
// (Delaunay-like) meshes such as the enriched S_P. The discrete shells
// energy is mesh dependent: on makeRectangleSheet's criss-cross grid the
// same sheet gets 1.48x the continuum energy for a cylinder along a grid
// axis and 1.00x along a diagonal (the valence-4 cell centres stiffen it);
// on a 15%-jittered lattice 1.0-1.1x.
double hingeStiffness(double bendingStiffness, double factor, double restEdgeLengthSquared,
                      double restArea0, double restArea1);

// Bending energy k (theta - restAngle)^2 (J) of a hinge ordered as in
// dihedralAngle, with gradient and Hessian when requested.
double bendingEnergy(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3,
                     double stiffness, double restAngle, Vec12* gradient = nullptr,
                     Mat12* hessian = nullptr);

// A grip (Grip, elastic_sheet.hpp): energy k/2 |w0 x0 + w1 x1 + w2 x2 - p|^2
// (J) of a zero-length spring (k in N/m) between a point of a triangle and
// its target p; gradient with respect to (x0, x1, x2) when requested. Its
// Hessian is constant, k (w w^T) (x) I_3.
double gripEnergy(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& weights,
                  const Vec3& target, double stiffness, Vec9* gradient = nullptr);

// Replace a symmetric matrix by its nearest positive semi-definite matrix
// (negative eigenvalues clamped to zero). Returns true when it changed.
bool projectToPsd(Mat9& m);
bool projectToPsd(Mat12& m);

// The same projection for the Hessian of a translation-invariant energy of
// 3 (Mat9) or 4 (Mat12) vertices, whose rows and columns sum to zero per
// axis: the eigenproblem is solved on the orthogonal complement of the rigid
// translations (6 x 6, 9 x 9), which holds its whole non-zero spectrum, so
// the result is the same nearest PSD matrix at a third to a half of the
// cost. The translation components of the result are exactly zero.
bool projectTranslationInvariantToPsd(Mat9& m);
bool projectTranslationInvariantToPsd(Mat12& m);

}  // namespace crumple::sim
