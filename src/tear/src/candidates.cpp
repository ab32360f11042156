#include "crumple/tear/candidates.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <stdexcept>

namespace crumple::tear {

namespace {

// The sheet's interior angle at every boundary vertex (-1 elsewhere): the
// sheet is on the left of its loop, so the angle at a vertex runs
// counter-clockwise from the outgoing edge to the incoming one; two edges
// along the same line are the tip of a slit (2 pi).
std::vector<double> interiorAngles(const mesh::SheetMesh& mesh) {
  std::vector<double> angle(mesh.vertexCount(), -1.0);
  for (const auto& loop : boundaryLoops(mesh)) {
    const std::size_t n = loop.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Vec2& prev = mesh.pattern[static_cast<std::size_t>(loop[(i + n - 1) % n])];
      const Vec2& here = mesh.pattern[static_cast<std::size_t>(loop[i])];
      const Vec2& next = mesh.pattern[static_cast<std::size_t>(loop[(i + 1) % n])];
      const Vec2 out1 = next - here, in1 = prev - here;
      double interior = std::atan2(out1.x() * in1.y() - out1.y() * in1.x(), out1.dot(in1));
      if (interior < 0.0) interior += 2.0 * std::numbers::pi;
      if (interior < 1e-9) interior = 2.0 * std::numbers::pi;
      angle[static_cast<std::size_t>(loop[i])] = interior;
    }
  }
  return angle;
}

}  // namespace

std::vector<int> inwardCorners(const mesh::SheetMesh& mesh, double minAngle) {
  std::vector<int> out;
  const std::vector<double> angle = interiorAngles(mesh);
  for (std::size_t v = 0; v < angle.size(); ++v)
    if (angle[v] > std::numbers::pi + minAngle) out.push_back(static_cast<int>(v));
  return out;
}

std::vector<TearCandidate> tearCandidates(const mesh::SheetMesh& mesh, const std::vector<int>& tips,
                                          const std::vector<int>& junctions,
                                          const std::vector<char>& held, double minInwardAngle) {
  if (held.size() != mesh.vertexCount())
    throw std::invalid_argument("tearCandidates: held must have one entry per vertex");
  std::map<int, CandidateKind> kind;
  const auto add = [&](int v, CandidateKind k) {
    if (v < 0 || static_cast<std::size_t>(v) >= mesh.vertexCount())
      throw std::invalid_argument("tearCandidates: vertex " + std::to_string(v) + " out of range");
    kind.emplace(v, k);  // the first kind given wins
  };
  // A convex corner of the outline (interior angle below 135 degrees) does
  // not start a tear: the material around it is the least loaded, and a
  // direction into the sheet from it runs along an edge.
  const std::vector<double> angle = interiorAngles(mesh);
  std::vector<char> convexCorner(mesh.vertexCount(), 0);
  for (std::size_t v = 0; v < angle.size(); ++v)
    convexCorner[v] = angle[v] >= 0.0 && angle[v] < 0.75 * std::numbers::pi ? 1 : 0;
  for (int v : tips) add(v, CandidateKind::Tip);
  for (int v : junctions)
    if (v < 0 || static_cast<std::size_t>(v) >= mesh.vertexCount() ||
        convexCorner[static_cast<std::size_t>(v)] == 0)
      add(v, CandidateKind::Junction);
  for (const auto& loop : boundaryLoops(mesh)) {
    const std::size_t n = loop.size();
    for (std::size_t i = 0; i < n; ++i) {
      const auto v = static_cast<std::size_t>(loop[i]);
      const auto before = static_cast<std::size_t>(loop[(i + n - 1) % n]);
      const auto after = static_cast<std::size_t>(loop[(i + 1) % n]);
      if (held[v] == 0 && convexCorner[v] == 0 && (held[before] != 0 || held[after] != 0))
        add(loop[i], CandidateKind::HandleBorder);
    }
  }
  for (int v : inwardCorners(mesh, minInwardAngle)) add(v, CandidateKind::InwardCorner);
  std::vector<TearCandidate> out;
  out.reserve(kind.size());
  for (const auto& [v, k] : kind) out.push_back({v, k});
  return out;
}

const char* candidateKindName(CandidateKind kind) {
  switch (kind) {
    case CandidateKind::Tip:
      return "tip";
    case CandidateKind::Junction:
      return "junction";
    case CandidateKind::HandleBorder:
      return "handle_border";
    case CandidateKind::InwardCorner:
      return "inward_corner";
  }
  return "?";
}

}  // namespace crumple::tear
