#include "crumple/tear/griffith.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace crumple::tear {

double fractureEnergy(double resistance, double fibers, double damage) {
  if (!(resistance >= 0.0) || !std::isfinite(resistance))
    throw std::invalid_argument("fractureEnergy: resistance C must be finite and >= 0");
  if (!(fibers >= 0.0 && fibers <= 1.0)) throw std::invalid_argument("fractureEnergy: T in [0, 1]");
  if (!(damage >= 0.0 && damage <= 1.0))
    throw std::invalid_argument("fractureEnergy: damage in [0, 1]");
  return resistance * fibers * damage;
}

namespace {

// The unit bisector of two vectors (their normalised sum), or zero.
Vec3 bisector(const Vec3& a, const Vec3& b) {
  const double na = a.norm(), nb = b.norm();
  if (!(na > 0.0) || !(nb > 0.0)) return (a + b).normalized();
  const Vec3 s = a / na + b / nb;
  const double ns = s.norm();
  return ns > 0.0 ? Vec3(s / ns) : Vec3::Zero();
}

}  // namespace

ForceClusters clusterTipForces(const std::vector<Vec3>& forces, const Vec3& normal,
                               const Vec3& tearDirection, int maxIterations) {
  if (!normal.allFinite() || !(normal.norm() > 0.0) || !tearDirection.allFinite() ||
      !(tearDirection.norm() > 0.0))
    throw std::invalid_argument("clusterTipForces: need a normal and a tear direction");
  const Vec3 n = normal.normalized();
  // b lies in the tangent plane.
  Vec3 b = tearDirection - tearDirection.dot(n) * n;
  if (!(b.norm() > 0.0)) throw std::invalid_argument("clusterTipForces: tear direction along n");
  b.normalize();
  ForceClusters out;
  for (int i = 0; i < std::max(1, maxIterations); ++i) {
    const Vec3 d = b.cross(n);
    Vec3 left = Vec3::Zero(), right = Vec3::Zero();
    out.side.assign(forces.size(), 0);
    for (std::size_t k = 0; k < forces.size(); ++k) {
      const double side = forces[k].dot(d);
      if (side > 0.0) left += forces[k], out.side[k] = 1;
      if (side < 0.0) right += forces[k], out.side[k] = -1;
    }
    out.left = left;
    out.right = right;
    out.iterations = i + 1;
    Vec3 next = bisector(left, right);
    next -= next.dot(n) * n;
    // The pulls' bisector points back between them; b keeps the sense of the
    // tear (the split plane is the same either way).
    if (next.dot(b) < 0.0) next = -next;
    if (!(next.norm() > 0.0)) break;
    next.normalize();
    if ((next - b).norm() < 1e-12) {
      out.converged = true;
      break;
    }
    b = next;
  }
  return out;
}

Propagation propagation(const Vec2& left, const Vec2& right) {
  Propagation p;
  const double nl = left.norm(), nr = right.norm();
  if (!(nl > 0.0) || !(nr > 0.0)) return p;
  const double c = std::clamp(left.dot(right) / (nl * nr), -1.0, 1.0);
  p.angle = std::acos(c);
  p.energyRelease = (nl + nr) * std::cos(0.5 * p.angle);
  const Vec2 pulls = left / nl + right / nr;
  if (pulls.norm() > 1e-12) p.direction = -pulls.normalized();
  return p;
}

Vec2 advanceTip(const Vec2& tip, const Propagation& p, double fractureEnergy, double speed) {
  if (!(p.energyRelease >= fractureEnergy) || !(p.direction.norm() > 0.0)) return tip;
  return tip + speed * p.energyRelease * p.direction;
}

}  // namespace crumple::tear
