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

void ElasticSheet::Impl::addAirGradient(const std::vector<Vec3>& xs, double h, VecX& out) const {
  const auto& frames = air->frames();
  const auto& forces = air->explicitForces();
  Vec9 g;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto& tri = triangles[t];
    airTriangleEnergy(frames[t], h, xs[static_cast<std::size_t>(tri[0])],
                      xs[static_cast<std::size_t>(tri[1])], xs[static_cast<std::size_t>(tri[2])],
                      &g);
    for (std::size_t a = 0; a < 3; ++a) {
      const int fi = freeIndex[static_cast<std::size_t>(tri[a])];
      if (fi >= 0) out.segment<3>(3 * fi) += g.segment<3>(3 * static_cast<int>(a));
    }
  }
  for (std::size_t i = 0; i < vertexCount; ++i)
    if (const int fi = freeIndex[i]; fi >= 0) out.segment<3>(3 * fi) -= forces[i];
}

void ElasticSheet::Impl::addAirHessian(const std::vector<Vec3>& xs, double h,
                                       double* values) const {
  const auto& frames = air->frames();
  Mat9 block;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto& tri = triangles[t];
    airTriangleEnergy(frames[t], h, xs[static_cast<std::size_t>(tri[0])],
                      xs[static_cast<std::size_t>(tri[1])], xs[static_cast<std::size_t>(tri[2])],
                      nullptr, &block);
    const int* off = triOffset.data() + 81 * t;
    for (int i = 0; i < 81; ++i)
      if (off[i] >= 0) values[off[i]] += block.data()[i];
  }
}

}  // namespace crumple::sim
