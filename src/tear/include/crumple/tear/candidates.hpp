#pragma once
// Potential tearing points of a frame (thesis 3.3.2): the tips of the tears,
// the junction points (boundary points between a flat and a curved region),
// the boundary points that bound a handle's held area, and the points where
// the pattern's boundary makes an inward angle. Only these are tested
// against the Griffith criterion each step.
#include <cstdint>
#include <vector>

#include "crumple/mesh/sheet_mesh.hpp"

namespace crumple::tear {

enum class CandidateKind : std::uint8_t { Tip, Junction, HandleBorder, InwardCorner };
// "tip", "junction", "handle_border" or "inward_corner" (summary.json, traces).
const char* candidateKindName(CandidateKind kind);

struct TearCandidate {
  int vertex = -1;
  CandidateKind kind = CandidateKind::Tip;
  bool operator==(const TearCandidate&) const = default;
};

// The boundary loops of the mesh's pattern (mesh/sheet_mesh.hpp).
using mesh::boundaryLoops;

// The boundary vertices where the sheet's interior angle in the pattern
// exceeds pi + minAngle (rad, >= 0): an inward corner, a notch's root.
std::vector<int> inwardCorners(const mesh::SheetMesh& mesh, double minAngle);

// The candidates of a frame, sorted by vertex, one per vertex (the first
// kind in the order Tip, Junction, HandleBorder, InwardCorner); junctions
// and held areas' borders at a convex corner of the outline (interior angle
// below 135 degrees) are not candidates:
// `tips` and `junctions` as given (junctions from paper::junctionVertices);
// boundary vertices that are not held but share an edge with a held one
// (held[v] != 0: the handles' vertices and their tangent-plane vertices);
// inwardCorners(mesh, minInwardAngle).
std::vector<TearCandidate> tearCandidates(const mesh::SheetMesh& mesh, const std::vector<int>& tips,
                                          const std::vector<int>& junctions,
                                          const std::vector<char>& held, double minInwardAngle);

}  // namespace crumple::tear
