#pragma once
// Internal to src/sim: rays from the sheet's faces upwind against the sheet
// itself (docs/AIR.md "Sheltering"), through a bounding volume hierarchy
// rebuilt at every step (median split on the longest axis).
#include <Eigen/Geometry>
#include <array>
#include <vector>

#include "crumple/core/types.hpp"

namespace crumple::sim {

// One triangle as the ray test reads it: a corner, the edges from it, and
// the determinant below which a ray lies in its plane.
struct ShelterFace {
  Vec3 origin, e1, e2;
  double flat = 0.0;
};

class ShelterCaster {
 public:
  void build(const std::vector<Vec3>& x, const std::vector<std::array<int, 3>>& triangles);
  // Distance from origin along the unit direction to the nearest triangle
  // that shares no vertex with triangle `self`, or maxDistance when none is
  // nearer.
  double hitDistance(std::size_t self, const Vec3& origin, const Vec3& direction,
                     double maxDistance) const;
  // Both ways along the line through origin with the unit direction, in one
  // traversal: {hitDistance along direction, hitDistance along -direction}
  // (bit for bit the two rays' answers).
  std::array<double, 2> lineHits(std::size_t self, const Vec3& origin, const Vec3& direction,
                                 double maxDistance) const;

 private:
  bool sharesVertex(std::size_t self, std::size_t other) const;
  struct Node {
    Eigen::AlignedBox3d box;
    int left = -1, right = -1;  // children, or -1 for a leaf
    int first = 0, count = 0;   // a leaf's triangles in order_
  };
  int buildNode(int first, int count, const std::vector<Vec3>& centroids);
  std::vector<Node> nodes_;
  std::vector<int> order_;
  std::vector<std::array<Vec3, 3>> corners_;  // for the boxes
  std::vector<ShelterFace> faces_;            // for the ray tests
  std::vector<std::array<int, 3>> ids_;
};

}  // namespace crumple::sim
