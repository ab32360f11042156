// Edge flips, coplanarity splits and merges, and folds turned into rulings
// (thesis 2.4.1; paper Sec. 5.1; docs/CRUMPLING.md "Folds become rulings").
#include <gtest/gtest.h>

#include <cmath>

#include "crumple/paper/geometric_step.hpp"
#include "crumple/paper/initial_sheet.hpp"

using namespace crumple;
using namespace crumple::paper;

namespace {

constexpr double kL = 0.10;

InitialSheet square() {
  return makeFlatSheet(kL, kL, {}, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY());
}

// The diagonal of the 2-triangle square (the edge both faces share).
std::pair<int, int> diagonal(const GeometricMesh& g) {
  for (const GeometricEdge& e : buildEdges(g)) {
    if (e.interior()) return {e.v[0], e.v[1]};
  }
  return {-1, -1};
}

// Folds the square about its diagonal through corners a and b by `angle`:
// the corners off the diagonal rise on either side.
void foldAboutDiagonal(GeometricMesh& g, int a, int b, double angle) {
  const Vec2 pa = g.vertices[static_cast<std::size_t>(a)].pattern;
  const Vec2 d = (g.vertices[static_cast<std::size_t>(b)].pattern - pa).normalized();
  for (GeometricVertex& v : g.vertices) {
    const Vec2 r = v.pattern - pa;
    const double along = r.dot(d);
    const double across = d.x() * r.y() - d.y() * r.x();  // signed distance from the diagonal
    const Vec2 foot = pa + along * d;
    const Vec2 n(-d.y(), d.x());
    const double half = 0.5 * angle;
    const Vec2 inPlane = foot + n * (across * std::cos(half));
    v.position = Vec3(inPlane.x(), inPlane.y(), std::abs(across) * std::sin(half));
  }
}

}  // namespace

TEST(FlatRegions, CompressedDiagonalIsFlippedToTheOtherOne) {
  InitialSheet s = square();
  GeometricMesh& g = s.mesh;
  const auto [a, b] = diagonal(g);
  ASSERT_GE(a, 0);
  // Pull the diagonal's ends 1 % closer (in the plane): it is compressed, the
  // other diagonal is not.
  const Vec3 mid = 0.5 * (g.vertices[static_cast<std::size_t>(a)].position +
                          g.vertices[static_cast<std::size_t>(b)].position);
  for (int v : {a, b}) {
    Vec3& x = g.vertices[static_cast<std::size_t>(v)].position;
    x = mid + 0.99 * (x - mid);
  }
  CrumpleParams params;
  EXPECT_EQ(flipCompressedEdges(g, params), 1);
  const auto [c, d] = diagonal(g);
  EXPECT_NE(std::make_pair(c, d), std::make_pair(std::min(a, b), std::max(a, b)));
  EXPECT_EQ(validate(g), "");
  // Nothing compressed: nothing flips.
  InitialSheet t = square();
  EXPECT_EQ(flipCompressedEdges(t.mesh, params), 0);
}

TEST(FlatRegions, FoldAboveTheta0SplitsAndUnfoldingMerges) {
  InitialSheet s = square();
  GeometricMesh& g = s.mesh;
  const auto [a, b] = diagonal(g);
  CrumpleParams params;
  foldAboutDiagonal(g, a, b, 0.5 * params.theta0);  // below theta_0: still one region
  EXPECT_EQ(splitFlatRegions(g, params), 0);
  EXPECT_EQ(g.regions.size(), 1u);
  foldAboutDiagonal(g, a, b, 3.0 * params.theta0);
  EXPECT_EQ(splitFlatRegions(g, params), 1);
  EXPECT_EQ(g.regions.size(), 2u);
  EXPECT_EQ(validate(g, params.theta0), "");  // each region planar within theta_0
  foldAboutDiagonal(g, a, b, 0.0);
  splitFlatRegions(g, params);
  EXPECT_EQ(g.regions.size(), 1u);  // coplanar again: merged
}

TEST(FlatRegions, AFoldBecomesRulingsAlongTheFoldedEdge) {
  InitialSheet s = square();
  GeometricMesh& g = s.mesh;
  const auto [a, b] = diagonal(g);
  CrumpleParams params;
  foldAboutDiagonal(g, a, b, 5.0 * params.theta0);
  GeometricStepStats stats;
  EXPECT_EQ(bendFoldedFlatRegions(g, params, nullptr, stats), 1);
  ASSERT_EQ(validate(g), "");
  const Vec2 d = (g.vertices[static_cast<std::size_t>(std::max(a, b))].pattern -
                  g.vertices[static_cast<std::size_t>(std::min(a, b))].pattern)
                     .normalized();
  int curved = 0;
  for (const Region& r : g.regions) {
    if (r.type != mesh::RegionType::Curved) continue;
    ++curved;
    for (const Ruling& ruling : r.rulings) {
      const Vec2 e = (g.vertices[static_cast<std::size_t>(ruling.b)].pattern -
                      g.vertices[static_cast<std::size_t>(ruling.a)].pattern)
                         .normalized();
      EXPECT_NEAR(std::abs(e.dot(d)), 1.0, 1e-9);  // parallel to the fold
    }
  }
  EXPECT_EQ(curved, 1);
  EXPECT_EQ(stats.curvedCreated, 1);
}
