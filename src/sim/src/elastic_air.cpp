// The air's terms in ElasticSheet's backward Euler step (sim/air.hpp,
// docs/AIR.md): the implicit drag and added mass of every triangle, and the
// explicit forces frozen at the step's start, as parts of the incremental
// potential.
#include "elastic_sheet_impl.hpp"

namespace crumple::sim {

double ElasticSheet::Impl::airEnergy(const std::vector<Vec3>& xs, double h) const {
  const auto& frames = air->frames();
  const auto& forces = air->explicitForces();
  double e = 0.0;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto& tri = triangles[t];
    e += airTriangleEnergy(frames[t], h, xs[static_cast<std::size_t>(tri[0])],
                           xs[static_cast<std::size_t>(tri[1])],
                           xs[static_cast<std::size_t>(tri[2])]);
  }
  for (std::size_t i = 0; i < vertexCount; ++i)
    if (freeIndex[i] >= 0) e -= forces[i].dot(xs[i]);
  return e;
}

void ElasticSheet::Impl::addAirGradient(const std::vector<Vec3>& xs, double h, VecX& out) {
  const auto& frames = air->frames();
  const auto& forces = air->explicitForces();
  airHess.resize(triangles.size());
  Vec9 g;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto& tri = triangles[t];
    const Vec3& x0 = xs[static_cast<std::size_t>(tri[0])];
    const Vec3& x1 = xs[static_cast<std::size_t>(tri[1])];
    const Vec3& x2 = xs[static_cast<std::size_t>(tri[2])];
    Mat3 centroidHessian;
    airTriangleEnergy(frames[t], h, x0, x1, x2, &g, nullptr, &centroidHessian);
    airHess[t] = centroidHessian / 9.0;
    for (std::size_t a = 0; a < 3; ++a) {
      const int fi = freeIndex[static_cast<std::size_t>(tri[a])];
      if (fi >= 0) out.segment<3>(3 * fi) += g.segment<3>(3 * static_cast<int>(a));
    }
  }
  for (std::size_t i = 0; i < vertexCount; ++i)
    if (const int fi = freeIndex[i]; fi >= 0) out.segment<3>(3 * fi) -= forces[i];
}

void ElasticSheet::Impl::scatterTrianglesWithAir(double dampScale, double* values) const {
  // airTriangleEnergy's Hessian is one 3 x 3 block repeated over the
  // vertex pairs: added to the membrane's before the one scatter.
  const bool damped = params.stiffnessDamping > 0.0;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    Mat9 block = triHess[t];
    if (damped) block += dampScale * triDamp[t];
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) block.block<3, 3>(3 * a, 3 * b) += airHess[t];
    const int* off = triOffset.data() + 81 * t;
    const double* bv = block.data();
    for (int i = 0; i < 81; ++i)
      if (off[i] >= 0) values[off[i]] += bv[i];
  }
}

}  // namespace crumple::sim
