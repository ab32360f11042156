#include "crumple/sim/self_contact.hpp"

#include <fcl/fcl.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <tuple>
#include <utility>

#include "crumple/sim/colliders.hpp"

namespace crumple::sim {

namespace {

Vec3 lift(const Vec2& p) { return {p.x(), p.y(), 0.0}; }

bool shareVertex(const std::array<int, 3>& a, const std::array<int, 3>& b) {
  for (int i : a)
    for (int j : b)
      if (i == j) return true;
  return false;
}

// The broad phase's callback: records triangle pairs whose grown boxes
// overlap and that share no vertex.
struct BroadPhaseData {
  const std::vector<std::array<int, 3>>* triangles = nullptr;
  std::vector<std::pair<int, int>> pairs;
};

bool recordPair(fcl::CollisionObjectd* a, fcl::CollisionObjectd* b, void* data) {
  auto* d = static_cast<BroadPhaseData*>(data);
  const auto ta = static_cast<int>(reinterpret_cast<std::intptr_t>(a->getUserData()));
  const auto tb = static_cast<int>(reinterpret_cast<std::intptr_t>(b->getUserData()));
  const auto& tris = *d->triangles;
  if (!shareVertex(tris[static_cast<std::size_t>(ta)], tris[static_cast<std::size_t>(tb)]))
    d->pairs.emplace_back(std::min(ta, tb), std::max(ta, tb));
  return false;  // never stop early: every pair is wanted
}

}  // namespace

struct SelfContactDetector::Impl {
  std::vector<std::array<int, 3>> triangles;
  std::vector<Vec2> pattern;
  double contactDistance = 0.0;
  std::vector<std::shared_ptr<fcl::Boxd>> boxes;
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects;
  std::unique_ptr<fcl::DynamicAABBTreeCollisionManagerd> manager;
  std::size_t lastPairs = 0;

  // Sizes triangle t's box to its bounds at xs and ys grown by reach / 2 on
  // every side (so two boxes overlap when the triangles may be within reach).
  void fitBox(std::size_t t, const std::vector<Vec3>& xs, const std::vector<Vec3>& ys,
              double reach) {
    const auto& tri = triangles[t];
    Vec3 lo = xs[static_cast<std::size_t>(tri[0])], hi = lo;
    for (int k = 0; k < 3; ++k) {
      const auto v = static_cast<std::size_t>(tri[static_cast<std::size_t>(k)]);
      lo = lo.cwiseMin(xs[v]).cwiseMin(ys[v]);
      hi = hi.cwiseMax(xs[v]).cwiseMax(ys[v]);
    }
    boxes[t]->side = (hi - lo) + Vec3::Constant(reach);
    boxes[t]->computeLocalAABB();
    objects[t]->setTranslation(0.5 * (lo + hi));
    objects[t]->computeAABB();
  }

  // Triangle pairs sharing no vertex whose boxes over xs and ys, grown by
  // reach / 2, overlap: FCL's dynamic AABB tree, built once and refitted per
  // call; sorted (the tree's traversal order depends on its history).
  std::vector<std::pair<int, int>> broadPhase(const std::vector<Vec3>& xs,
                                              const std::vector<Vec3>& ys, double reach) {
    const std::size_t nt = triangles.size();
    if (!manager) {
      manager = std::make_unique<fcl::DynamicAABBTreeCollisionManagerd>();
      std::vector<fcl::CollisionObjectd*> all;
      for (std::size_t t = 0; t < nt; ++t) {
        boxes.push_back(std::make_shared<fcl::Boxd>(1.0, 1.0, 1.0));
        objects.push_back(std::make_unique<fcl::CollisionObjectd>(boxes.back()));
        objects.back()->setUserData(reinterpret_cast<void*>(static_cast<std::intptr_t>(t)));
        fitBox(t, xs, ys, reach);
        all.push_back(objects.back().get());
      }
      manager->registerObjects(all);
      manager->setup();
    } else {
      for (std::size_t t = 0; t < nt; ++t) fitBox(t, xs, ys, reach);
      manager->update();
    }
    BroadPhaseData data;
    data.triangles = &triangles;
    manager->collide(&data, recordPair);
    std::sort(data.pairs.begin(), data.pairs.end());
    data.pairs.erase(std::unique(data.pairs.begin(), data.pairs.end()), data.pairs.end());
    lastPairs = data.pairs.size();
    return std::move(data.pairs);
  }

  // The pattern distance from point pv (lifted) to pattern triangle t.
  double patternDistance(const Vec3& pv, std::size_t t) const {
    const Vec3 pa = lift(pattern[static_cast<std::size_t>(triangles[t][0])]);
    const Vec3 pb = lift(pattern[static_cast<std::size_t>(triangles[t][1])]);
    const Vec3 pc = lift(pattern[static_cast<std::size_t>(triangles[t][2])]);
    const std::array<double, 3> pw = closestBarycentricOnTriangle(pv, pa, pb, pc);
    return (pv - (pw[0] * pa + pw[1] * pb + pw[2] * pc)).norm();
  }
};

SelfContactDetector::SelfContactDetector(std::vector<std::array<int, 3>> triangles,
                                         std::vector<Vec2> pattern, double contactDistance)
    : impl_(std::make_unique<Impl>()) {
  if (!(contactDistance > 0.0) || !std::isfinite(contactDistance))
    throw std::invalid_argument("SelfContactDetector: contact distance must be > 0");
  for (const auto& t : triangles)
    for (int v : t)
      if (v < 0 || static_cast<std::size_t>(v) >= pattern.size())
        throw std::invalid_argument("SelfContactDetector: triangle index out of range");
  impl_->triangles = std::move(triangles);
  impl_->pattern = std::move(pattern);
  impl_->contactDistance = contactDistance;
}

SelfContactDetector::~SelfContactDetector() = default;
SelfContactDetector::SelfContactDetector(SelfContactDetector&&) noexcept = default;
SelfContactDetector& SelfContactDetector::operator=(SelfContactDetector&&) noexcept = default;

std::size_t SelfContactDetector::broadPhasePairs() const { return impl_->lastPairs; }

std::vector<SelfContactPair> SelfContactDetector::find(const std::vector<Vec3>& xs, double reach,
                                                       const std::vector<char>* vertexMask) {
  return find(xs, xs, reach, vertexMask);
}

std::vector<SelfContactPair> SelfContactDetector::find(const std::vector<Vec3>& xs,
                                                       const std::vector<Vec3>& ys, double reach,
                                                       const std::vector<char>* vertexMask) {
  Impl& m = *impl_;
  if (!(reach > 0.0) || !std::isfinite(reach))
    throw std::invalid_argument("SelfContactDetector::find: margin must be > 0");
  if (xs.size() != m.pattern.size() || ys.size() != m.pattern.size())
    throw std::invalid_argument("SelfContactDetector::find: positions do not match the sheet");
  const auto pairs = m.broadPhase(xs, ys, reach);

  // Narrow phase: each vertex of one triangle against the other triangle.
  const double exclusion = kSelfContactRestExclusion * m.contactDistance;
  std::vector<SelfContactPair> out;
  auto test = [&](int vertex, int triangle) {
    const auto vi = static_cast<std::size_t>(vertex);
    if (vertexMask != nullptr && (*vertexMask)[vi] == 0) return;
    const auto& t = m.triangles[static_cast<std::size_t>(triangle)];
    const Vec3& a = xs[static_cast<std::size_t>(t[0])];
    const Vec3& b = xs[static_cast<std::size_t>(t[1])];
    const Vec3& c = xs[static_cast<std::size_t>(t[2])];
    const std::array<double, 3> w = closestBarycentricOnTriangle(xs[vi], a, b, c);
    const Vec3 q = w[0] * a + w[1] * b + w[2] * c;
    const double d = (xs[vi] - q).norm();
    double moves = (ys[vi] - xs[vi]).norm();
    double triangleMoves = 0.0;
    for (int k : t)
      triangleMoves =
          std::max(triangleMoves,
                   (ys[static_cast<std::size_t>(k)] - xs[static_cast<std::size_t>(k)]).norm());
    moves += triangleMoves;
    if (!(d < reach + moves)) return;
    // Material neighbours are one layer, not two.
    if (m.patternDistance(lift(m.pattern[vi]), static_cast<std::size_t>(triangle)) < exclusion)
      return;
    SelfContactPair p;
    p.vertex = vertex;
    p.triangle = triangle;
    p.weights = w;
    p.distance = d;
    const Vec3 face = (b - a).cross(c - a);
    const double area2 = face.squaredNorm();
    if (area2 > 0.0) {
      // Over the face: the projection's barycentric coordinates are >= 0.
      const Vec3 r = xs[vi] - a;
      const Vec3 n = face / std::sqrt(area2);
      const double wb = (r.cross(c - a)).dot(face) / area2;
      const double wc = ((b - a).cross(r)).dot(face) / area2;
      constexpr double kOnEdge = 1e-9;
      p.face = wb >= -kOnEdge && wc >= -kOnEdge && 1.0 - wb - wc >= -kOnEdge;
      if (p.face) p.normal = n.dot(r) >= 0.0 ? n : Vec3(-n);
    }
    if (!p.face && d > 1e-9 * m.contactDistance) p.normal = (xs[vi] - q) / d;
    out.push_back(p);
  };
  for (const auto& [ta, tb] : pairs) {
    for (int v : m.triangles[static_cast<std::size_t>(ta)]) test(v, tb);
    for (int v : m.triangles[static_cast<std::size_t>(tb)]) test(v, ta);
  }
  std::sort(out.begin(), out.end(), [](const SelfContactPair& l, const SelfContactPair& r) {
    return l.vertex != r.vertex ? l.vertex < r.vertex : l.triangle < r.triangle;
  });
  out.erase(std::unique(out.begin(), out.end(),
                        [](const SelfContactPair& l, const SelfContactPair& r) {
                          return l.vertex == r.vertex && l.triangle == r.triangle;
                        }),
            out.end());
  // A vertex over some face keeps its face contacts only.
  std::vector<SelfContactPair> kept;
  kept.reserve(out.size());
  for (std::size_t i = 0; i < out.size();) {
    std::size_t j = i;
    bool anyFace = false;
    for (; j < out.size() && out[j].vertex == out[i].vertex; ++j) anyFace = anyFace || out[j].face;
    for (std::size_t k = i; k < j; ++k)
      if (out[k].face || !anyFace) kept.push_back(out[k]);
    i = j;
  }
  return kept;
}

std::vector<SelfCrossing> SelfContactDetector::crossings(const std::vector<Vec3>& xs) {
  Impl& m = *impl_;
  if (xs.size() != m.pattern.size())
    throw std::invalid_argument("SelfContactDetector::crossings: positions do not match the sheet");
  const double exclusion = kSelfContactRestExclusion * m.contactDistance;
  std::vector<SelfCrossing> out;
  // Segment p-q against triangle t (Moller & Trumbore 1997 in its
  // plane-side form): strictly opposite sides, the crossing point inside.
  auto test = [&](int a, int b, int triangle) {
    const auto& t = m.triangles[static_cast<std::size_t>(triangle)];
    const Vec3& p = xs[static_cast<std::size_t>(a)];
    const Vec3& q = xs[static_cast<std::size_t>(b)];
    const Vec3& ta = xs[static_cast<std::size_t>(t[0])];
    const Vec3 e1 = xs[static_cast<std::size_t>(t[1])] - ta;
    const Vec3 e2 = xs[static_cast<std::size_t>(t[2])] - ta;
    const Vec3 face = e1.cross(e2);
    const double area2 = face.squaredNorm();
    if (!(area2 > 0.0)) return;
    const Vec3 n = face / std::sqrt(area2);
    const double sp = n.dot(p - ta), sq = n.dot(q - ta);
    if (!(sp * sq < 0.0)) return;
    const double s = sp / (sp - sq);
    const Vec3 r = p + s * (q - p) - ta;
    const double wb = r.cross(e2).dot(face) / area2;
    const double wc = e1.cross(r).dot(face) / area2;
    if (wb < 0.0 || wc < 0.0 || wb + wc > 1.0) return;
    const Vec2 pv = (1.0 - s) * m.pattern[static_cast<std::size_t>(a)] +
                    s * m.pattern[static_cast<std::size_t>(b)];
    if (m.patternDistance(lift(pv), static_cast<std::size_t>(triangle)) < exclusion) return;
    out.push_back({std::min(a, b), std::max(a, b), triangle, std::min(std::abs(sp), std::abs(sq))});
  };
  const double reach = 1e-3 * m.contactDistance;
  for (const auto& [ta, tb] : m.broadPhase(xs, xs, reach))
    for (const auto& [from, to] : {std::pair{ta, tb}, std::pair{tb, ta}}) {
      const auto& t = m.triangles[static_cast<std::size_t>(from)];
      for (int k = 0; k < 3; ++k)
        test(t[static_cast<std::size_t>(k)], t[static_cast<std::size_t>((k + 1) % 3)], to);
    }
  std::sort(out.begin(), out.end(), [](const SelfCrossing& l, const SelfCrossing& r) {
    return std::tie(l.a, l.b, l.triangle) < std::tie(r.a, r.b, r.triangle);
  });
  out.erase(std::unique(out.begin(), out.end(),
                        [](const SelfCrossing& l, const SelfCrossing& r) {
                          return l.a == r.a && l.b == r.b && l.triangle == r.triangle;
                        }),
            out.end());
  return out;
}

bool sheetIsFolded(const std::vector<std::array<int, 3>>& triangles, const std::vector<Vec3>& xs,
                   double maxSpread) {
  Vec3 mean = Vec3::Zero();
  std::vector<Vec3> normals;
  normals.reserve(triangles.size());
  for (const auto& t : triangles) {
    const Vec3 n =
        (xs[static_cast<std::size_t>(t[1])] - xs[static_cast<std::size_t>(t[0])])
            .cross(xs[static_cast<std::size_t>(t[2])] - xs[static_cast<std::size_t>(t[0])]);
    mean += n;  // |n| = twice the area: area-weighted
    const double len = n.norm();
    if (len > 0.0) normals.push_back(n / len);
  }
  const double len = mean.norm();
  if (!(len > 0.0)) return !normals.empty();
  mean /= len;
  const double cosMax = std::cos(maxSpread);
  return std::any_of(normals.begin(), normals.end(),
                     [&](const Vec3& n) { return n.dot(mean) < cosMax; });
}

}  // namespace crumple::sim
