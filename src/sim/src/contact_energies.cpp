#include "crumple/sim/contact_energies.hpp"

#include "crumple/sim/colliders.hpp"

namespace crumple::sim {

double VertexContact::gap(const Vec3& x, double distance, Vec3* direction) const {
  if (!toTriangle) {
    if (direction != nullptr) *direction = normal;
    return distance - normal.dot(x - point);
  }
  const Vec3 d = x - closestPointOnTriangle(x, triangle[0], triangle[1], triangle[2]);
  const double len = d.norm();
  if (direction != nullptr) *direction = len > 0.0 ? Vec3(d / len) : normal;
  return distance - len;
}

bool VertexContact::penalty(const Vec3& x, double distance, double& energy, Vec3* gradient,
                            Mat3* hessian) const {
  Vec3 dir;
  const double g = gap(x, distance, &dir);
  if (!(g > 0.0)) return false;
  energy = 0.5 * k * g * g;
  if (gradient != nullptr) *gradient = -(k * g * dir);
  if (hessian != nullptr) *hessian = k * dir * dir.transpose();
  return true;
}

double VertexContact::friction(const Vec3& x, const Vec3& xStart, double eps, Vec3* gradient,
                               Mat3* hessian) const {
  if (!(mu > 0.0) || !(lambda > 0.0)) return 0.0;
  const Mat3 t = Mat3::Identity() - normal * normal.transpose();
  const Vec3 u = t * ((x - xStart) - motion);
  const double y = u.norm();
  const double scale = mu * lambda;
  const double f0 = y >= eps ? y : -y * y * y / (3.0 * eps * eps) + y * y / eps + eps / 3.0;
  if (gradient != nullptr) {
    const double f1OverY = y >= eps ? 1.0 / y : -y / (eps * eps) + 2.0 / eps;
    const double f1Prime = y >= eps ? 0.0 : -2.0 * y / (eps * eps) + 2.0 / eps;
    *gradient = scale * f1OverY * u;
    if (hessian != nullptr) {
      Mat3 inner = f1OverY * Mat3::Identity();
      if (y > 1e-300) {
        const Vec3 d = u / y;
        inner += (f1Prime - f1OverY) * d * d.transpose();
      }
      *hessian = scale * t * inner * t;
    }
  }
  return scale * f0;
}

double FaceContact::gap(const Vec3& x0, const Vec3& x1, const Vec3& x2, double distance) const {
  Vec3 q = Vec3::Zero();
  q += w[0] * x0;
  q += w[1] * x1;
  q += w[2] * x2;
  return radius + distance - normal.dot(q - probe);
}

bool FaceContact::penalty(const Vec3& x0, const Vec3& x1, const Vec3& x2, double distance,
                          double& energy, Vec9* gradient, Mat9* hessian) const {
  const double g = gap(x0, x1, x2, distance);
  if (!(g > 0.0)) return false;
  energy = 0.5 * k * g * g;
  if (gradient != nullptr)
    for (std::size_t a = 0; a < 3; ++a)
      gradient->segment<3>(3 * static_cast<int>(a)) = -(k * g * w[a] * normal);
  if (hessian != nullptr) {
    Vec9 d;
    for (int a = 0; a < 3; ++a) d.segment<3>(3 * a) = w[static_cast<std::size_t>(a)] * normal;
    *hessian = k * d * d.transpose();
  }
  return true;
}

}  // namespace crumple::sim
