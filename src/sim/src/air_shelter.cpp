// Sheltering rays (air_shelter.hpp): a BVH over the sheet's triangles and
// Moller & Trumbore 1997's ray-triangle test.
#include "air_shelter.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace crumple::sim {

namespace {

constexpr int kLeafSize = 4;

// The part [t0, t1] of the line o + t d inside the box, clipped to the given
// [t0, t1]; false when empty.
bool clipToBox(const Eigen::AlignedBox3d& box, const Vec3& o, const Vec3& inv, double& t0,
               double& t1) {
  for (int a = 0; a < 3; ++a) {
    double near = (box.min()(a) - o(a)) * inv(a), far = (box.max()(a) - o(a)) * inv(a);
    if (near > far) std::swap(near, far);
    // NaN (0 * inf, a line in the slab's plane) leaves the bound as it was.
    if (near > t0) t0 = near;
    if (far < t1) t1 = far;
    if (t0 > t1) return false;
  }
  return true;
}

// The ray's entry distance into the box, or +inf when it misses it within maxT.
double enterBox(const Eigen::AlignedBox3d& box, const Vec3& o, const Vec3& inv, double maxT) {
  double t0 = 0.0, t1 = maxT;
  return clipToBox(box, o, inv, t0, t1) ? t0 : std::numeric_limits<double>::infinity();
}

// Moller & Trumbore 1997: the signed distance along d at which the line
// through o meets the face, or NaN when it misses it or lies in its plane.
// Along -d the test gives exactly the negated distance (every product
// changes sign exactly), so one call serves both directions.
double lineTriangle(const Vec3& o, const Vec3& d, const ShelterFace& f) {
  constexpr double kMiss = std::numeric_limits<double>::quiet_NaN();
  const Vec3 p = d.cross(f.e2);
  const double det = f.e1.dot(p);
  // A ray in the triangle's plane does not hit it.
  if (std::abs(det) <= f.flat) return kMiss;
  const double inv = 1.0 / det;
  const Vec3 s = o - f.origin;
  const double u = s.dot(p) * inv;
  if (u < 0.0 || u > 1.0) return kMiss;
  const Vec3 q = s.cross(f.e1);
  const double v = d.dot(q) * inv;
  if (v < 0.0 || u + v > 1.0) return kMiss;
  return f.e2.dot(q) * inv;
}

// The ray's distance to the face, or +inf.
double rayTriangle(const Vec3& o, const Vec3& d, const ShelterFace& f) {
  const double t = lineTriangle(o, d, f);
  return t > 0.0 ? t : std::numeric_limits<double>::infinity();
}

}  // namespace

void ShelterCaster::build(const std::vector<Vec3>& x,
                          const std::vector<std::array<int, 3>>& triangles) {
  const std::size_t n = triangles.size();
  ids_ = triangles;
  corners_.resize(n);
  faces_.resize(n);
  std::vector<Vec3> centroids(n);
  for (std::size_t t = 0; t < n; ++t) {
    for (std::size_t a = 0; a < 3; ++a)
      corners_[t][a] = x[static_cast<std::size_t>(triangles[t][a])];
    centroids[t] = (corners_[t][0] + corners_[t][1] + corners_[t][2]) / 3.0;
    ShelterFace& f = faces_[t];
    f.origin = corners_[t][0];
    f.e1 = corners_[t][1] - corners_[t][0];
    f.e2 = corners_[t][2] - corners_[t][0];
    f.flat = 1e-12 * f.e1.norm() * f.e2.norm();
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

bool ShelterCaster::sharesVertex(std::size_t self, std::size_t other) const {
  bool shares = false;
  for (int a : ids_[self])
    for (int b : ids_[other]) shares = shares || a == b;
  return shares;
}

std::array<double, 2> ShelterCaster::lineHits(std::size_t self, const Vec3& origin,
                                              const Vec3& direction, double maxDistance) const {
  // best[0] along +direction, best[1] along -direction: the nodes whose box
  // the line crosses within (-best[1], best[0]) are searched.
  std::array<double, 2> best{maxDistance, maxDistance};
  if (nodes_.empty()) return best;
  const Vec3 inv = direction.cwiseInverse();
  std::array<int, 64> stack{};
  int top = 0;
  stack[static_cast<std::size_t>(top++)] = 0;
  while (top > 0) {
    const Node& node = nodes_[static_cast<std::size_t>(stack[static_cast<std::size_t>(--top)])];
    if (double t0 = -best[1], t1 = best[0]; !clipToBox(node.box, origin, inv, t0, t1)) continue;
    if (node.left < 0) {
      for (int i = node.first; i < node.first + node.count; ++i) {
        const auto t = static_cast<std::size_t>(order_[static_cast<std::size_t>(i)]);
        if (sharesVertex(self, t)) continue;
        const double along = lineTriangle(origin, direction, faces_[t]);
        if (along > 0.0) best[0] = std::min(best[0], along);
        if (along < 0.0) best[1] = std::min(best[1], -along);
      }
      continue;
    }
    if (top + 2 > static_cast<int>(stack.size()))
      throw std::length_error("ShelterCaster: too deep");
    stack[static_cast<std::size_t>(top++)] = node.right;
    stack[static_cast<std::size_t>(top++)] = node.left;
  }
  return best;
}

double ShelterCaster::hitDistance(std::size_t self, const Vec3& origin, const Vec3& direction,
                                  double maxDistance) const {
  if (nodes_.empty()) return maxDistance;
  const Vec3 inv = direction.cwiseInverse();
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
        if (sharesVertex(self, t)) continue;
        best = std::min(best, rayTriangle(origin, direction, faces_[t]));
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
