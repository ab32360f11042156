#pragma once
// When and where a tear runs (thesis 3.3.1-3.3.3): the Griffith criterion
// E_r >= E_f at a candidate tearing point, the fracture energy from the
// fibers' texture and the tip damage, the forces at the point clustered into
// two opposite pulls, and the tip's advance along their bisector.
#include <vector>

#include "crumple/core/types.hpp"

namespace crumple::tear {

// The fracture energy of a candidate point (thesis 3.3.2): E_f = C T d_p,
// with C the paper's general resistance (0.005 by default), T the fibers'
// texture at the point (in [0, 1]) and d_p the damage: D (in [0, 1]) at the
// tip of a tear, 1 elsewhere.
double fractureEnergy(double resistance, double fibers, double damage);

// The forces on a candidate point split into two opposite pulls (thesis
// 3.3.3, Figs. 3.17-3.18): starting from the tear direction b^0, each
// iteration sums the forces on either side of the plane through b^i and the
// surface normal n (d^i = b^i x n: f.d^i > 0 is left) and takes b^{i+1} as
// the bisector of the two sums; it stops when b no longer changes, or after
// maxIterations.
struct ForceClusters {
  Vec3 left = Vec3::Zero();
  Vec3 right = Vec3::Zero();
  std::vector<int> side;  // per force: +1 left, -1 right, 0 on the split plane
  int iterations = 0;
  bool converged = false;
};
ForceClusters clusterTipForces(const std::vector<Vec3>& forces, const Vec3& normal,
                               const Vec3& tearDirection, int maxIterations = 10);

// The tear's response to two pulls at its tip, in the pattern (thesis 3.3.1
// eq. (3.4), 3.3.3). The pulls are the forces with which the two sides draw
// the material at the tip toward them (a flap pulled toward A draws the tip
// toward A): with theta the angle between them, E_r = (|L| + |R|) cos(theta
// / 2), and the tip runs away from them along the bisector of the
// directions from the pulling points to the tip (Roman 2013: the bisector
// of AS and BS), i.e. opposite the pulls' bisector. Two pulls straight
// apart (theta = pi) release nothing: they stretch the sheet across the
// tear instead of opening it.
struct Propagation {
  double energyRelease = 0.0;     // E_r (N: energy per unit of new tear length)
  Vec2 direction = Vec2::Zero();  // unit, in the pattern; zero when the pulls cancel
  double angle = 0.0;             // theta (rad), in [0, pi]
};
Propagation propagation(const Vec2& left, const Vec2& right);

// The next tip (thesis 3.3.3): s + V E_r d when E_r >= E_f, else s.
Vec2 advanceTip(const Vec2& tip, const Propagation& p, double fractureEnergy, double speed);

}  // namespace crumple::tear
