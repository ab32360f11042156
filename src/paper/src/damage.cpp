#include "crumple/paper/damage.hpp"

#include <stdexcept>

#include "crumple/core/index.hpp"

namespace crumple::paper {

// thesis eqs. (2.1)-(2.2)
std::vector<HingeDamage> fiberDamage(const mesh::SheetMesh& sp,
                                     const std::vector<mesh::MeshEdge>& hinges,
                                     const std::vector<char>& singular,
                                     const std::vector<double>& hingeAngles,
                                     const CrumpleParams& params) {
  if (hingeAngles.size() != hinges.size())
    throw std::invalid_argument("fiberDamage: one angle per hinge expected");
  // N_i: edges around every vertex (boundary edges included).
  std::vector<int> degree(sp.vertexCount(), 0);
  for (const mesh::MeshEdge& e : mesh::buildEdges(sp)) {
    ++degree[idx(e.v[0])];
    ++degree[idx(e.v[1])];
  }
  const auto isSingular = [&](int v) { return inRange(singular, v) && singular[idx(v)] != 0; };
  std::vector<HingeDamage> out(hinges.size());
  for (std::size_t h = 0; h < hinges.size(); ++h) {
    double theta = 0.0;
    double d = 0.0;
    for (int v : hinges[h].v) {
      if (!isSingular(v)) continue;
      const double n = static_cast<double>(std::max(degree[idx(v)], 1));
      theta += params.thetaRest / n;
      d += params.damage / n;
    }
    out[h].restAngle = hingeAngles[h] < 0.0 ? -theta : theta;
    out[h].stiffnessFactor = 1.0 / (1.0 + d);
  }
  return out;
}

}  // namespace crumple::paper
