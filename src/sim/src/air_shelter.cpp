// Sheltering rays (air_shelter.hpp): a BVH over the sheet's triangles and
// Moller & Trumbore 1997's ray-triangle test.
#include "air_shelter.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace crumple::sim {

namespace {

constexpr int kLeafSize = 4;

// The ray's entry distance into the box, or +inf when it misses it within maxT.
double enterBox(const Eigen::AlignedBox3d& box, const Vec3& o, const Vec3& inv, double maxT) {
  double t0 = 0.0, t1 = maxT;
  for (int a = 0; a < 3; ++a) {
    double near = (box.min()(a) - o(a)) * inv(a), far = (box.max()(a) - o(a)) * inv(a);
    if (near > far) std::swap(near, far);
    // NaN (0 * inf, a ray in the slab's plane) leaves the bound as it was.
    if (near > t0) t0 = near;
    if (far < t1) t1 = far;
    if (t0 > t1) return std::numeric_limits<double>::infinity();
  }
  return t0;
}

// Moller & Trumbore 1997: the ray's distance to the triangle, or +inf.
double rayTriangle(const Vec3& o, const Vec3& d, const std::array<Vec3, 3>& c) {
  const Vec3 e1 = c[1] - c[0], e2 = c[2] - c[0];
  const Vec3 p = d.cross(e2);
  const double det = e1.dot(p);
  // A ray in the triangle's plane does not hit it.
  if (std::abs(det) <= 1e-12 * e1.norm() * e2.norm())
    return std::numeric_limits<double>::infinity();
  const double inv = 1.0 / det;
  const Vec3 s = o - c[0];
  const double u = s.dot(p) * inv;
  if (u < 0.0 || u > 1.0) return std::numeric_limits<double>::infinity();
  const Vec3 q = s.cross(e1);
  const double v = d.dot(q) * inv;
  if (v < 0.0 || u + v > 1.0) return std::numeric_limits<double>::infinity();
  const double t = e2.dot(q) * inv;
  return t > 0.0 ? t : std::numeric_limits<double>::infinity();
}

}  // namespace

void ShelterCaster::build(const std::vector<Vec3>& x,
                          const std::vector<std::array<int, 3>>& triangles) {
  const std::size_t n = triangles.size();
  ids_ = triangles;
  corners_.resize(n);
  std::vector<Vec3> centroids(n);
  for (std::size_t t = 0; t < n; ++t) {
    for (std::size_t a = 0; a < 3; ++a)
      corners_[t][a] = x[static_cast<std::size_t>(triangles[t][a])];
    centroids[t] = (corners_[t][0] + corners_[t][1] + corners_[t][2]) / 3.0;
  }
  order_.resize(n);
  for (std::size_t t = 0; t < n; ++t) order_[t] = static_cast<int>(t);
  nodes_.clear();
  nodes_.reserve(2 * n / kLeafSize + 2);
  if (n > 0) buildNode(0, static_cast<int>(n), centroids);
}

int ShelterCaster::buildNode(int first, int count, const std::vector<Vec3>& centroids) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.push_back(Node{});
  Eigen::AlignedBox3d box, centres;
  for (int i = first; i < first + count; ++i) {
    const auto t = static_cast<std::size_t>(order_[static_cast<std::size_t>(i)]);
    for (const Vec3& c : corners_[t]) box.extend(c);
    centres.extend(centroids[t]);
  }
  nodes_[static_cast<std::size_t>(index)].box = box;
  if (count <= kLeafSize) {
    nodes_[static_cast<std::size_t>(index)].first = first;
    nodes_[static_cast<std::size_t>(index)].count = count;
    return index;
  }
  int axis = 0;
  centres.sizes().maxCoeff(&axis);
  const int half = count / 2;
  // Ties broken by index: the same tree whatever the standard library.
  std::nth_element(order_.begin() + first, order_.begin() + first + half,
                   order_.begin() + first + count, [&](int a, int b) {
                     const double ca = centroids[static_cast<std::size_t>(a)](axis);
                     const double cb = centroids[static_cast<std::size_t>(b)](axis);
                     return ca < cb || (ca == cb && a < b);
                   });
  const int left = buildNode(first, half, centroids);
  const int right = buildNode(first + half, count - half, centroids);
  nodes_[static_cast<std::size_t>(index)].left = left;
  nodes_[static_cast<std::size_t>(index)].right = right;
  return index;
}

double ShelterCaster::hitDistance(std::size_t self, const Vec3& origin, const Vec3& direction,
                                  double maxDistance) const {
  if (nodes_.empty()) return maxDistance;
  const Vec3 inv = direction.cwiseInverse();
  const auto& mine = ids_[self];
  double best = maxDistance;
  // A median-split tree over n triangles is about log2(n / kLeafSize) deep:
  // 64 entries hold any mesh that fits in memory.
  struct Entry {
    int node = 0;
    double enter = 0.0;  // the ray's entry distance into the node's box
  };
  std::array<Entry, 64> stack{};
  int top = 0;
  if (const double enter = enterBox(nodes_.front().box, origin, inv, best); enter < best)
    stack[static_cast<std::size_t>(top++)] = {0, enter};
  while (top > 0) {
    const Entry entry = stack[static_cast<std::size_t>(--top)];
    if (!(entry.enter < best)) continue;  // a nearer hit was found since it was pushed
    const Node& node = nodes_[static_cast<std::size_t>(entry.node)];
    if (node.left < 0) {
      for (int i = node.first; i < node.first + node.count; ++i) {
        const auto t = static_cast<std::size_t>(order_[static_cast<std::size_t>(i)]);
        const auto& other = ids_[t];
        bool shares = false;
        for (int a : mine)
          for (int b : other) shares = shares || a == b;
        if (shares) continue;
        best = std::min(best, rayTriangle(origin, direction, corners_[t]));
      }
      continue;
    }
    if (top + 2 > static_cast<int>(stack.size()))
      throw std::length_error("ShelterCaster: too deep");
    // The nearer child is searched first (pushed last), so a hit in it
    // prunes the farther one; the nearest hit is the same in any order.
    const std::array<Entry, 2> children{
        Entry{node.left,
              enterBox(nodes_[static_cast<std::size_t>(node.left)].box, origin, inv, best)},
        Entry{node.right,
              enterBox(nodes_[static_cast<std::size_t>(node.right)].box, origin, inv, best)}};
    const std::size_t nearer = children[1].enter < children[0].enter ? 1 : 0;
    for (const std::size_t c : {1 - nearer, nearer})
      if (children[c].enter < best) stack[static_cast<std::size_t>(top++)] = children[c];
  }
  return best;
}

}  // namespace crumple::sim
