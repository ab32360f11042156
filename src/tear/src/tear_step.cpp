#include "crumple/tear/tear_step.hpp"

#include <stdexcept>

namespace crumple::tear {

std::vector<CandidateTest> testCandidates(const mesh::SheetMesh& mesh, const FiberTexture& fibers,
                                          const std::vector<int>& tips,
                                          const std::vector<int>& junctions,
                                          const std::vector<char>& held, const VertexForces& forces,
                                          const TearParams& params) {
  if (!forces) throw std::invalid_argument("testCandidates: no force source");
  std::vector<CandidateTest> out;
  for (const TearCandidate& c :
       tearCandidates(mesh, tips, junctions, held, params.minInwardAngle)) {
    CandidateTest test;
    test.candidate = c;
    const Vec2& at = mesh.pattern[static_cast<std::size_t>(c.vertex)];
    test.next = at;
    const double damage = c.kind == CandidateKind::Tip ? params.tipDamage : 1.0;
    test.fractureEnergy = fractureEnergy(params.resistance, fibers.sample(at), damage);
    const std::vector<TriangleForce> f = forces(c.vertex);
    bool any = false;
    for (const TriangleForce& tf : f) any = any || tf.force.norm() > 0.0;
    if (any) {
      const TipPulls pulls = tipPulls(mesh, c.vertex, f, boundaryBisector(mesh, c.vertex));
      test.propagation = propagation(pulls.left, pulls.right);
      test.tears = test.propagation.energyRelease >= test.fractureEnergy &&
                   test.propagation.direction.norm() > 0.0;
      test.next = advanceTip(at, test.propagation, test.fractureEnergy, params.speed);
    }
    out.push_back(test);
  }
  return out;
}

}  // namespace crumple::tear
