#pragma once
// Developer trace of the hybrid model's animation steps (internal to
// crumple::paper): with CRUMPLE_DEBUG_GEOMETRY=1 one block per step on
// stderr (region counts, remeshing, c_mean before and after the isometry,
// largest speed and hinge angle, worst S_P triangle, declined remeshings);
// =2 adds S_G's vertices and faces, =3 the eight worst S_P edges.
#include <array>
#include <vector>

#include "crumple/paper/hybrid_sheet.hpp"

namespace crumple::paper::detail {

// The trace level from CRUMPLE_DEBUG_GEOMETRY (0: off), read once.
int stepTraceLevel();

// Largest |dihedral angle| over S_P's hinges (rad).
double maxHingeAngle(const sim::ElasticSheet& elastic);

// Prints the trace of one animation step of frame `frame` at `level`.
// `pinned`: the pins at the step's end; `hinge`: the largest hinge angle
// after the elastic step, the S_P rebuild and the isometry; `elasticStrain`:
// the largest edge strain of S_P as the elastic step left it.
void printStepTrace(int level, int frame, const GeometricMesh& sg, const PhysicalMesh& sp,
                    const sim::ElasticSheet& elastic, const HybridStepStats& stats,
                    const std::vector<sim::Pin>& pinned, const std::array<double, 3>& hinge,
                    double elasticStrain);

// Developer aid: with CRUMPLE_DEBUG_DUMP=FILE, the S_P of a failed step as
// OBJ (pattern as comments; `geometricCount`: its first vertices are S_G's).
void dumpFailedStep(const mesh::SheetMesh& sp, std::size_t geometricCount);

}  // namespace crumple::paper::detail
