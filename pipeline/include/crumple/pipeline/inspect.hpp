#pragma once
// Per-frame measures of a cached shot (`crumple inspect`): sizes, edge strain
// against the pattern (c_mean and n_comp as in paper Table IV), sharpest
// fold between adjacent triangles, handle error, contacts (the COLL / CONT
// sub-blocks, exporters/pcache_contacts.hpp).
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/cache/pcache_structure.hpp"
#include "crumple/mesh/sheet_mesh.hpp"

namespace crumple::pipeline {

struct FrameMetrics {
  int frame = 0;
  double time = 0.0;
  std::size_t vertices = 0;
  std::size_t triangles = 0;
  double cMean = 0.0;        // mean |l - L| / L over edges (paper Table IV, c_mean)
  double nComp = 0.0;        // share of edges with (L - l) / L > 1% (paper Table IV, n_comp)
  double maxStrain = 0.0;    // max |l - L| / L over edges
  double maxDihedral = 0.0;  // largest angle (rad) between the normals of adjacent triangles
  double handleError = 0.0;  // max distance between a held vertex and its track (m)
  std::size_t singularVertices = 0;
  std::size_t junctionVertices = 0;
  std::size_t tears = 0;
  std::size_t contacts = 0;    // records in the frame's CONT block (0 without one)
  double maxSlideSpeed = 0.0;  // largest slide speed among them (m/s)
  // Developability: the angle defect 2 pi - sum of corner angles (rad) at the
  // interior vertices that are not singular (0 on a developable surface).
  double meanAngleDefect = 0.0;    // mean |defect| over them
  double maxAngleDefect = 0.0;     // max |defect| over them
  double totalAngleDefect = 0.0;   // sum of |defect| (discrete total |K| dA, resolution-free)
  std::size_t defectVertices = 0;  // how many were measured
  double popping = 0.0;            // poppingMeasure against the frame before (0 on the first)
  Vec3 extent = Vec3::Zero();      // side lengths of the sheet's axis-aligned bounding box (m)
  // The crumpling model's structure changes in the frame (its STRC block;
  // nullopt for a frame of the elastic model or an older cache).
  std::optional<cache::StructureChanges> structure;
  double selfDepth = 0.0;         // selfPenetration(...).depth (0 without a thickness)
  std::size_t selfCrossings = 0;  // selfPenetration(...).crossings
  // The falling-paper regimes (docs/AIR.md): the sheet's centre of mass
  // (uniform density over the pattern), the unit area-weighted mean of its
  // triangles' normals (zero when they cancel) and that normal's angle from
  // the world's up axis +y (deg, 0 level face up, 180 face down).
  Vec3 centroid = Vec3::Zero();
  Vec3 meanNormal = Vec3::Zero();
  double normalAngleDeg = 0.0;
  // (centroid - the frame before's) / time between them (m/s; 0 on the first).
  Vec3 centroidVelocity = Vec3::Zero();
};

// How far the sheet passes into itself, for a paper of thickness h (m, from
// the cache header): the deepest that one layer reaches into another, in h
// (a vertex nearer than h to a triangle of another layer: (h - distance) / h;
// an edge through such a triangle: 1 + how far it reaches past the plane / h,
// so any crossing counts as more than a whole thickness), and how many edges
// pass through a triangle. Every vertex counts, held or not, unless
// `vertexMask` leaves it out of the pairs ((*vertexMask)[v] == 0; crossings
// count every edge); material neighbours are one layer
// (sim::SelfContactDetector).
struct SelfPenetration {
  double depth = 0.0;  // in thicknesses
  std::size_t crossings = 0;
};
SelfPenetration selfPenetration(const cache::FrameRecord& frame, double thickness,
                                const std::vector<char>* vertexMask = nullptr);

// The angle defect of a triangle mesh (Gauss-Bonnet's discrete curvature):
// |2 pi - sum of the corner angles| at each vertex that is not on a boundary
// edge (an edge of one triangle) and not in `excluded` (the singular
// vertices, where the crumpling model concentrates the curvature).
struct AngleDefect {
  double mean = 0.0;   // rad
  double max = 0.0;    // rad
  double total = 0.0;  // rad, the sum
  std::size_t vertices = 0;
};
AngleDefect angleDefect(const std::vector<std::array<int, 3>>& triangles,
                        const std::vector<Vec3>& positions, const std::vector<int>& excluded);

// Throws CorruptDataError naming the frame for a malformed CONT block.
FrameMetrics measureFrame(const cache::FrameRecord& frame);

// The sheet's mass distribution: the centroid and radius of gyration of its
// surface, each triangle weighted by its pattern (material) area, uniform
// over the triangle: unchanged when the same surface is triangulated
// anew.
struct SheetMoments {
  Vec3 centroid = Vec3::Zero();  // m
  double gyration = 0.0;         // m, sqrt of the mean squared distance to the centroid
};
SheetMoments sheetMoments(const std::vector<std::array<int, 3>>& triangles,
                          const std::vector<Vec2>& pattern, const std::vector<Vec3>& positions);

// The popping measure between two consecutive frames: the change of the
// sheet's centroid and of its radius of gyration (the larger), over 3 x
// (the largest displacement of a handle's track between them + 1 mm).
// Above 1 the sheet jumped more than its handles moved it: a pop when S_P's
// connectivity changed (paper Sec. 7.4, limitation 3). Handles are matched
// by index; a frame pair with different handle counts uses the common ones.
double poppingMeasure(const cache::FrameRecord& previous, const cache::FrameRecord& current);
// The cached frame as a sheet mesh (pattern, positions, triangles, regions),
// e.g. for mesh::validate.
mesh::SheetMesh sheetOfFrame(const cache::FrameRecord& frame);

// The notice for a cache recovered without its footer (a killed or still
// running shot): the file, and how many of the header's planned frames it
// holds. Empty for a complete cache. `render`, `sound` and `export` print it
// on stderr and in their closing summary.
std::string recoveredNote(const cache::CacheReader& reader);

// The `inspect --json` object: {"format_version", "fps", "frame_count",
// "recovered", "planned_frames", "frames": [...]} -- later features extend it but never rename a
// key. A cache whose header has COLL adds "colliders": [{"name", "material", "friction"}] and, per
// frame, "contacts" and "max_slide_speed" (m/s). Every frame has "angle_defect_mean",
// "angle_defect_max", "angle_defect_total" (rad), "angle_defect_vertices", "popping" and "extent"
// ([x, y, z], m: the bounding box of the sheet) (FrameMetrics).
std::string inspectJson(const cache::CacheReader& reader);
// The human-readable table (with the colliders and a contacts and a max
// slide speed column when the header has COLL).
std::string inspectText(const cache::CacheReader& reader);

}  // namespace crumple::pipeline
