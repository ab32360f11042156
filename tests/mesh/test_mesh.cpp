#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>

#include "crumple/mesh/sheet_mesh.hpp"

using namespace crumple;
using namespace crumple::mesh;

TEST(RectangleSheet, IsAValidCrissCrossGrid) {
  const auto m = makeRectangleSheet(0.21, 0.297, 0.03);
  EXPECT_EQ(validate(m), "");
  // 7 x 10 cells, 4 triangles each, corners + centres as vertices.
  EXPECT_EQ(m.triangleCount(), 7u * 10u * 4u);
  EXPECT_EQ(m.vertexCount(), 8u * 11u + 7u * 10u);
  double area = 0.0;
  for (const auto& t : m.triangles) {
    const Vec2 e1 = m.pattern[t[1]] - m.pattern[t[0]];
    const Vec2 e2 = m.pattern[t[2]] - m.pattern[t[0]];
    const double a = 0.5 * (e1.x() * e2.y() - e1.y() * e2.x());
    EXPECT_GT(a, 0.0) << "triangles are counter-clockwise in the pattern";
    area += a;
  }
  EXPECT_NEAR(area, 0.21 * 0.297, 1e-12);
  // Every corner of the sheet is a vertex.
  for (const Vec2& c : {Vec2(0, 0), Vec2(0.21, 0), Vec2(0, 0.297), Vec2(0.21, 0.297)})
    EXPECT_LT((m.pattern[nearestPatternVertex(m, c)] - c).norm(), 1e-12);
}

TEST(BuildEdges, CountsHingesAndBoundary) {
  const auto m = makeRectangleSheet(1.0, 1.0, 0.5);  // 2 x 2 cells
  const auto edges = buildEdges(m);
  int boundary = 0, interior = 0;
  for (const auto& e : edges) {
    EXPECT_LT(e.v[0], e.v[1]);
    if (e.interior()) {
      ++interior;
      for (int k = 0; k < 2; ++k) {
        const auto& t = m.triangles[e.triangles[k]];
        const int opp = e.opposite[k];
        EXPECT_TRUE(opp != e.v[0] && opp != e.v[1]);
        EXPECT_TRUE(t[0] == opp || t[1] == opp || t[2] == opp);
      }
    } else {
      ++boundary;
    }
  }
  EXPECT_EQ(boundary, 8);
  // Euler: E = V + F - 1 for a disc; V = 9 + 4, F = 16.
  EXPECT_EQ(boundary + interior, 13 + 16 - 1);
}

TEST(BuildEdges, RejectsNonManifold) {
  SheetMesh m;
  m.pattern = {Vec2(0, 0), Vec2(1, 0), Vec2(0, 1), Vec2(1, 1), Vec2(0.5, -1)};
  m.positions.assign(5, Vec3::Zero());
  m.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
  EXPECT_THROW(buildEdges(m), std::invalid_argument);
}

TEST(Validate, FindsBadMeshes) {
  auto m = makeRectangleSheet(1.0, 1.0, 1.0);
  EXPECT_EQ(validate(m), "");
  auto bad = m;
  bad.triangles[0][1] = 99;
  EXPECT_NE(validate(bad), "");
  bad = m;
  bad.positions[0].x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(validate(bad), "");
  bad = m;
  bad.pattern[bad.triangles[0][1]] = bad.pattern[bad.triangles[0][0]];
  EXPECT_NE(validate(bad), "");
}

TEST(PlacePattern, MapsAxes) {
  auto m = makeRectangleSheet(2.0, 1.0, 1.0);
  placePattern(m, Vec3(1, 2, 3), Vec3::UnitZ(), Vec3::UnitY());
  for (std::size_t i = 0; i < m.vertexCount(); ++i)
    EXPECT_TRUE(m.positions[i].isApprox(Vec3(1, 2 + m.pattern[i].y(), 3 + m.pattern[i].x())));
  EXPECT_EQ(vertexNeighbours(m, 0).size(), 3u);  // a corner: two sides and the cell centre
}

TEST(RectangleSheet, RejectsBadSizes) {
  EXPECT_THROW(makeRectangleSheet(-1.0, 1.0, 0.1), std::invalid_argument);
  EXPECT_THROW(makeRectangleSheet(1.0, 0.0, 0.1), std::invalid_argument);
  EXPECT_THROW(makeRectangleSheet(1.0, 1.0, std::numeric_limits<double>::quiet_NaN()),
               std::invalid_argument);
}

namespace crumple::mesh {
namespace {

TEST(PolygonSheet, AnLShapeIsCoveredExactlyWithEveryOutlinePointAVertex) {
  const std::vector<Vec2> outline = {{0, 0},       {0.12, 0},    {0.12, 0.05},
                                     {0.05, 0.05}, {0.05, 0.10}, {0, 0.10}};
  const SheetMesh m = makePolygonSheet(outline, 0.005);
  EXPECT_EQ(validate(m), "");
  double area = 0.0, longest = 0.0;
  for (const auto& t : m.triangles) {
    const Vec2 a = m.pattern[static_cast<std::size_t>(t[0])];
    const Vec2 b = m.pattern[static_cast<std::size_t>(t[1])];
    const Vec2 c = m.pattern[static_cast<std::size_t>(t[2])];
    const double cross = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    EXPECT_GT(cross, 0.0) << "counter-clockwise";
    area += 0.5 * cross;
    longest = std::max({longest, (b - a).norm(), (c - b).norm(), (a - c).norm()});
  }
  EXPECT_NEAR(area, 0.0085, 1e-12);
  EXPECT_LT(longest, 2.0 * 0.005) << "no edge longer than twice max_edge";
  for (const Vec2& p : outline)
    EXPECT_LT((m.pattern[static_cast<std::size_t>(nearestPatternVertex(m, p))] - p).norm(), 1e-12);
  EXPECT_THROW(makePolygonSheet({{0, 0}, {0, 1}, {1, 0}}, 0.1), std::invalid_argument)
      << "clockwise";
  EXPECT_THROW(makePolygonSheet(outline, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace crumple::mesh

// locatePattern: a point inside the pattern is the weighted sum of its
// triangle's corners (weights >= 0, summing to 1); a point on the border is
// inside; a point beyond it is in no triangle.
TEST(LocatePattern, GivesTheTriangleAndWeightsOfAPatternPoint) {
  const SheetMesh m = makeRectangleSheet(0.1, 0.05, 0.02);
  for (const Vec2& p :
       {Vec2(0.013, 0.027), Vec2(0.0999, 0.0001), Vec2(0.05, 0.0), Vec2(0.0, 0.05)}) {
    const PatternLocation at = locatePattern(m, p);
    ASSERT_GE(at.triangle, 0) << p.transpose();
    const auto& t = m.triangles[static_cast<std::size_t>(at.triangle)];
    Vec2 q = Vec2::Zero();
    for (int c = 0; c < 3; ++c) q += at.weights(c) * m.pattern[static_cast<std::size_t>(t[c])];
    EXPECT_LT((q - p).norm(), 1e-15) << p.transpose();
    EXPECT_NEAR(at.weights.sum(), 1.0, 1e-12);
    EXPECT_GE(at.weights.minCoeff(), -1e-12);
  }
  EXPECT_EQ(locatePattern(m, Vec2(0.101, 0.02)).triangle, -1);
  EXPECT_EQ(locatePattern(m, Vec2(0.05, -1e-6)).triangle, -1);
}
