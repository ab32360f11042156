#pragma once
// The 3D boundary curve of the sheet: the outline dS of the pattern as it
// currently lies in space, sampled at the boundary vertices of S_P and
// interpolated with cubics in the outline parameter s (paper Sec. 6.2: "the
// 3D coordinates of the newly sampled vertices are finally reported on the
// 3D boundary curve using cubic interpolation"; thesis 2.5.2; paper
// Appendix B). New ruling endpoints created by the cone fit
// (cone_fit.hpp) get their 3D position from here.
#include <span>
#include <vector>

#include "crumple/core/types.hpp"
#include "crumple/mesh/boundary_curve.hpp"
#include "crumple/paper/geometric_mesh.hpp"

namespace crumple::paper {

// The curve itself lives in the mesh module (renderers refine with it).
using mesh::BoundaryCurve;
using mesh::BoundarySample;

// The boundary curve of a mesh whose vertices have pattern positions
// `pattern` and 3D positions `positions` (S_P: mesh::SheetMesh::pattern and
// ::positions; or S_G's vertices): every vertex whose pattern point lies on
// the outline of `g` within `tolerance` (m) is a sample; the outline
// corners are breaks. Throws std::invalid_argument when the spans differ in
// size or no vertex lies on the outline.
BoundaryCurve boundaryCurveFromMesh(const GeometricMesh& g, std::span<const Vec2> pattern,
                                    std::span<const Vec3> positions, double tolerance = 1e-9);

// Outline parameters of the corners of g.outline (corner i at s_i, s_0 = 0).
std::vector<double> outlineCornerParameters(const GeometricMesh& g);

}  // namespace crumple::paper
