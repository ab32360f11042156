#pragma once
// Internal helpers shared by the remeshing steps of src/paper (not installed).
#include <algorithm>
#include <array>
#include <functional>
#include <optional>
#include <span>
#include <stdexcept>
#include <utility>
#include <vector>

#include "crumple/paper/geometric_mesh.hpp"

namespace crumple::paper::detail {

// The S_G edges, (min, max) vertex pair -> the two faces (-1: none), as a
// vector sorted by key: built once per remeshing and searched many times,
// so one allocation beats a node per edge (the remeshing steps rebuild it
// per region; it was a third of the hybrid model's run time as a std::map).
class EdgeMap {
 public:
  using Key = std::pair<int, int>;
  using value_type = std::pair<Key, std::array<int, 2>>;
  using const_iterator = std::vector<value_type>::const_iterator;

  EdgeMap() = default;
  explicit EdgeMap(std::vector<value_type> sorted) : entries_(std::move(sorted)) {}
  const_iterator begin() const { return entries_.begin(); }
  const_iterator end() const { return entries_.end(); }
  std::size_t size() const { return entries_.size(); }
  const_iterator find(const Key& key) const {
    const auto it =
        std::lower_bound(entries_.begin(), entries_.end(), key,
                         [](const value_type& entry, const Key& k) { return entry.first < k; });
    return it != entries_.end() && it->first == key ? it : entries_.end();
  }
  // The faces of edge `key`; throws std::out_of_range when there is no such edge.
  const std::array<int, 2>& at(const Key& key) const {
    const auto it = find(key);
    if (it == entries_.end()) throw std::out_of_range("EdgeMap: no such S_G edge");
    return it->second;
  }

 private:
  std::vector<value_type> entries_;
};

EdgeMap edgeMap(const GeometricMesh& g);

// edgeMap(g), rebuilt only when g's faces changed since the last call: the
// remeshing loops look at every region in turn and most leave S_G as it was.
// The returned map stays valid until the next call.
class EdgeMapCache {
 public:
  const EdgeMap& of(const GeometricMesh& g) {
    if (!valid_ || faces_ != g.faces) {
      map_ = edgeMap(g);
      faces_ = g.faces;
      valid_ = true;
    }
    return map_;
  }

 private:
  bool valid_ = false;
  std::vector<GeometricFace> faces_;
  EdgeMap map_;
};

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
