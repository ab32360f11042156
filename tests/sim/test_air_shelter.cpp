// The sheltering rays' tree (src/sim/src/air_shelter.hpp, docs/AIR.md
// "Sheltering"): the one traversal along both ways of a line answers what
// the two rays answer, bit for bit, and both agree with testing every
// triangle.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "air_shelter.hpp"
#include "fd_check.hpp"

using namespace crumple;
using namespace crumple::sim;
using crumple::testing::Random;

namespace {

// A soup of small triangles in a 10 cm box, some sharing vertices.
struct Soup {
  std::vector<Vec3> x;
  std::vector<std::array<int, 3>> triangles;
};

Soup randomSoup(std::uint64_t seed, int count) {
  Random r(seed);
  Soup s;
  for (int i = 0; i < count; ++i) {
    const Vec3 c = r.vec3(0.05);
    const int base = static_cast<int>(s.x.size());
    for (int a = 0; a < 3; ++a) s.x.push_back(c + r.vec3(0.01));
    // Every fifth triangle reuses a corner of the one before.
    s.triangles.push_back({i % 5 == 4 ? base - 1 : base, base + 1, base + 2});
  }
  return s;
}

// The nearest hit along a ray over every triangle sharing no vertex with
// `self` (the brute-force answer).
double bruteForce(const Soup& s, std::size_t self, const Vec3& o, const Vec3& d, double reach) {
  double best = reach;
  for (std::size_t t = 0; t < s.triangles.size(); ++t) {
    bool shares = false;
    for (int a : s.triangles[self])
      for (int b : s.triangles[t]) shares = shares || a == b;
    if (shares) continue;
    const Vec3 c0 = s.x[static_cast<std::size_t>(s.triangles[t][0])];
    const Vec3 e1 = s.x[static_cast<std::size_t>(s.triangles[t][1])] - c0;
    const Vec3 e2 = s.x[static_cast<std::size_t>(s.triangles[t][2])] - c0;
    const Vec3 p = d.cross(e2);
    const double det = e1.dot(p);
    if (std::abs(det) <= 1e-12 * e1.norm() * e2.norm()) continue;
    const Vec3 q = (o - c0).cross(e1);
    const double u = (o - c0).dot(p) / det, v = d.dot(q) / det, along = e2.dot(q) / det;
    if (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && along > 0.0) best = std::min(best, along);
  }
  return best;
}

}  // namespace

TEST(ShelterCaster, OneTraversalBothWaysIsTheTwoRaysBitForBit) {
  const Soup s = randomSoup(7, 400);
  ShelterCaster caster;
  caster.build(s.x, s.triangles);
  Random r(11);
  int hits = 0;
  for (std::size_t t = 0; t < s.triangles.size(); ++t) {
    const Vec3 o = (s.x[static_cast<std::size_t>(s.triangles[t][0])] +
                    s.x[static_cast<std::size_t>(s.triangles[t][1])] +
                    s.x[static_cast<std::size_t>(s.triangles[t][2])]) /
                   3.0;
    const Vec3 d = r.vec3(1.0).normalized();
    const double reach = 0.06;
    const std::array<double, 2> both = caster.lineHits(t, o, d, reach);
    const double forward = caster.hitDistance(t, o, d, reach);
    const double backward = caster.hitDistance(t, o, -d, reach);
    EXPECT_EQ(both[0], forward) << "triangle " << t;
    EXPECT_EQ(both[1], backward) << "triangle " << t;
    EXPECT_NEAR(forward, bruteForce(s, t, o, d, reach), 1e-12) << "triangle " << t;
    EXPECT_NEAR(backward, bruteForce(s, t, o, -d, reach), 1e-12) << "triangle " << t;
    hits += (forward < reach) + (backward < reach);
  }
  // The soup is dense enough that most lines meet something.
  EXPECT_GT(hits, 200);
}
