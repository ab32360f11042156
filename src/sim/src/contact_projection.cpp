#include <chrono>

#include "crumple/sim/colliders.hpp"
#include "crumple/sim/elastic_sheet.hpp"
#include "crumple/sim/self_contact.hpp"

namespace crumple::sim {

void projectOutOfContacts(const ContactOptions& contact,
                          const std::vector<std::array<int, 3>>& triangles,
                          const std::vector<Vec2>& pattern, const std::vector<char>& held,
                          std::vector<Vec3>& x, double* collidersMs, double* selfMs) {
  using Clock = std::chrono::steady_clock;
  const auto since = [](Clock::time_point t) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
  };
  auto t0 = Clock::now();
  const double dist = contact.distance;
  const double minGap = (1.0 - kContactFailsafeSlack) * dist;
  if (contact.colliders != nullptr && contact.colliders->size() > 0) {
    for (std::size_t i = 0; i < x.size(); ++i) {
      if (held[i] != 0) continue;
      if (const auto c = contact.colliders->nearest(x[i], dist); c && c->distance < minGap)
        x[i] += (dist - c->distance) * c->normal;
    }
    // A ball's centre or a box's corner near the inside of a face: the
    // face's free vertices move out.
    for (const ColliderProbe& p : contact.colliders->probes()) {
      for (const auto& t : triangles) {
        const Vec3 q = closestPointOnTriangle(p.point, x[static_cast<std::size_t>(t[0])],
                                              x[static_cast<std::size_t>(t[1])],
                                              x[static_cast<std::size_t>(t[2])]);
        const double d = (q - p.point).norm();
        if (!(d < p.radius + minGap) || !(d > 0.0)) continue;
        const Vec3 out = (p.radius + dist - d) * (q - p.point) / d;
        for (int v : t)
          if (held[static_cast<std::size_t>(v)] == 0) x[static_cast<std::size_t>(v)] += out;
      }
    }
  }
  if (collidersMs != nullptr) *collidersMs += since(t0);
  t0 = Clock::now();
  if (contact.self == SelfContactMode::On ||
      (contact.self == SelfContactMode::Auto && sheetIsFolded(triangles, x, contact.foldSpread))) {
    std::vector<char> free(x.size(), 0);
    for (std::size_t i = 0; i < x.size(); ++i) free[i] = held[i] == 0 ? 1 : 0;
    SelfContactDetector detector(triangles, pattern, dist);
    for (const SelfContactPair& p : detector.find(x, dist, &free)) {
      if (!(p.distance < minGap)) continue;
      const auto& t = triangles[static_cast<std::size_t>(p.triangle)];
      Vec3 q = Vec3::Zero();
      for (std::size_t k = 0; k < 3; ++k) q += p.weights[k] * x[static_cast<std::size_t>(t[k])];
      x[static_cast<std::size_t>(p.vertex)] = q + dist * p.normal;
    }
  }
  if (selfMs != nullptr) *selfMs += since(t0);
}

}  // namespace crumple::sim
