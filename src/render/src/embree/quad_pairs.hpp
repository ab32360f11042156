#pragma once
// Private to the path tracer: a triangle mesh handed to Embree as quads, two
// triangles that share an edge in each (Embree's quad primitive: half the
// primitives of the same surface, so a smaller BVH; Embree manual,
// RTC_GEOMETRY_TYPE_QUAD), and the way back from a quad hit to the triangle
// and barycentrics the shading reads.
#include "frame_data.hpp"

namespace crumple::render::pt {

// Pairs m's triangles across shared edges (consistently oriented, two
// triangles an edge) into m.quads and m.quadTriangles, coplanar pairs
// first, then the most nearly coplanar, the longer shared edge first among
// equals (so a planar cell split along its diagonal becomes one quad); a
// triangle left alone is a quad (a, b, c, c). The paired triangles' corners
// are rotated so that Embree's split of the quad gives them back: the first
// is (q0, q1, q3), the second (q2, q3, q1). Every per-corner array follows
// the rotation: `look`'s shading normals, texture and mask coordinates,
// singular-corner bits and motion steps' normals, when given (the sheet).
// Deterministic: a function of the mesh alone.
void pairIntoQuads(MeshData& m, SheetLook* look);

}  // namespace crumple::render::pt
