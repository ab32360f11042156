#pragma once
// Internal helpers shared by the remeshing steps of src/paper (not installed).
#include <array>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <vector>

#include "crumple/paper/geometric_mesh.hpp"

namespace crumple::paper::detail {

using EdgeMap = std::map<std::pair<int, int>, std::array<int, 2>>;  // (min, max) -> faces

EdgeMap edgeMap(const GeometricMesh& g);

// The face across edge (a, b) from `face`, or -1.
int otherFace(const EdgeMap& edges, int a, int b, int face);

// The boundary loop of a region, counter-clockwise: v[k] -> v[k+1] with the
// face across it (-1 on dS).
struct Loop {
  std::vector<int> v;
  std::vector<int> across;
  std::size_t size() const { return v.size(); }
  int next(std::size_t k) const { return v[(k + 1) % v.size()]; }
};

// nullopt when the region has several loops (holes) or pinches.
std::optional<Loop> regionLoop(const GeometricMesh& g, int region, const EdgeMap& edges);

// Point-in-polygon test (even-odd rule) for a polygon of S_G vertices.
bool pointInPolygon(const GeometricMesh& g, std::span<const int> polygon, const Vec2& p);

// Point-in-polygon test against the loop (even-odd rule).
bool insideLoop(const GeometricMesh& g, const Loop& loop, const Vec2& p);

// Vertices of the region's faces that are not on its loop.
std::vector<int> innerVertices(const GeometricMesh& g, int region, const Loop& loop);

// Outline segment nearest to a pattern point.
int nearestOutlineSegment(const GeometricMesh& g, const Vec2& p);

// Builds flat faces for a polygon (vertex ids, CCW) by constrained Delaunay;
// the `inner` vertices strictly inside it are kept as vertices.
void triangulatePolygon(GeometricMesh& g, const std::vector<int>& polygon, int region,
                        const std::vector<int>& inner = {});

// Appends an empty region of the given type and returns its id.
int addRegion(GeometricMesh& g, mesh::RegionType type);

// A new vertex on the dS edge (a, b) at pattern point p, its 3D position on
// the boundary curve (or interpolated along the edge when `boundary` is empty).
int addBoundaryVertex(GeometricMesh& g, int a, int b, const Vec2& p,
                      const std::function<Vec3(double)>& boundary);

}  // namespace crumple::paper::detail
