#include "crumple/tear/detail_path.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace crumple::tear {

namespace {

double distanceToSegment(const Vec2& q, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((q - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (q - (a + t * ab)).norm();
}

}  // namespace

double breakingCoefficient(const FiberTexture& fibers, const Vec2& q, const Vec2& from,
                           const Vec2& to, const DetailPathParams& params) {
  const double d = distanceToSegment(q, from, to);
  const double g = std::exp(-0.5 * d * d / (params.stressWidth * params.stressWidth));
  return (1.0 - params.blend) * fibers.sample(q) + params.blend * g;
}

std::vector<Vec2> detailPath(const FiberTexture& fibers, const Vec2& from, const Vec2& to,
                             const DetailPathParams& params) {
  if (!(params.blend >= 0.0 && params.blend <= 1.0))
    throw std::invalid_argument("detailPath: blend p must be in [0, 1]");
  if (!(params.stressWidth > 0.0) || !std::isfinite(params.stressWidth))
    throw std::invalid_argument("detailPath: stress width must be > 0");
  if (!from.allFinite() || !to.allFinite())
    throw std::invalid_argument("detailPath: endpoints must be finite");
  std::vector<Vec2> path{from};
  const auto target = fibers.texelOf(to);
  auto at = fibers.texelOf(from);
  const int straight = std::max(std::abs(target[0] - at[0]), std::abs(target[1] - at[1]));
  constexpr std::array<std::array<int, 2>, 8> kNeighbours{
      {{1, 0}, {1, 1}, {0, 1}, {-1, 1}, {-1, 0}, {-1, -1}, {0, -1}, {1, -1}}};
  for (int step = 0; step < 4 * straight + 4 && at != target; ++step) {
    // Next to the end: the walk is there.
    if (std::max(std::abs(target[0] - at[0]), std::abs(target[1] - at[1])) <= 1) {
      at = target;
      path.push_back(fibers.centre(at[0], at[1]));
      break;
    }
    const Vec2 here = fibers.centre(at[0], at[1]);
    const Vec2 toward = fibers.centre(target[0], target[1]) - here;
    double best = -1.0;
    std::array<int, 2> next = at;
    for (const auto& [di, dj] : kNeighbours) {
      const int i = at[0] + di, j = at[1] + dj;
      if (i < 0 || j < 0 || i >= fibers.width() || j >= fibers.height()) continue;
      // Only forward: within pi/2 of the direction to the target.
      if (!(Vec2(di, dj).dot(toward) > 0.0)) continue;
      const double nu = breakingCoefficient(fibers, fibers.centre(i, j), from, to, params);
      if (nu > best) {  // ties keep the first neighbour in the fixed order
        best = nu;
        next = {i, j};
      }
    }
    if (next == at) break;
    at = next;
    path.push_back(fibers.centre(at[0], at[1]));
  }
  path.push_back(to);
  return path;
}

double pathLength(const std::vector<Vec2>& path) {
  double length = 0.0;
  for (std::size_t i = 1; i < path.size(); ++i) length += (path[i] - path[i - 1]).norm();
  return length;
}

}  // namespace crumple::tear
