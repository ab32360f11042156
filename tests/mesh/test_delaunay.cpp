// Constrained Delaunay triangulation (paper Sec. 4 "Enriching the coarse mesh").
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <set>
#include <stdexcept>
#include <utility>

#include "crumple/mesh/delaunay.hpp"

using namespace crumple;
using namespace crumple::mesh;

namespace {

using Triangles = std::vector<std::array<int, 3>>;
using Segments = std::vector<std::array<int, 2>>;

double signedArea(const std::vector<Vec2>& p, const std::array<int, 3>& t) {
  const Vec2 e1 = p[t[1]] - p[t[0]];
  const Vec2 e2 = p[t[2]] - p[t[0]];
  return 0.5 * (e1.x() * e2.y() - e1.y() * e2.x());
}

double polygonArea(const std::vector<Vec2>& p, const std::vector<int>& loop) {
  double a = 0.0;
  for (std::size_t i = 0; i < loop.size(); ++i) {
    const Vec2& u = p[loop[i]];
    const Vec2& v = p[loop[(i + 1) % loop.size()]];
    a += 0.5 * (u.x() * v.y() - u.y() * v.x());
  }
  return a;
}

// Closed loop of constraints through consecutive indices.
void addLoop(Segments& s, const std::vector<int>& loop) {
  for (std::size_t i = 0; i < loop.size(); ++i) s.push_back({loop[i], loop[(i + 1) % loop.size()]});
}

bool hasEdge(const Triangles& tris, int a, int b) {
  for (const auto& t : tris)
    for (int k = 0; k < 3; ++k)
      if ((t[k] == a && t[(k + 1) % 3] == b) || (t[k] == b && t[(k + 1) % 3] == a)) return true;
  return false;
}

// Every triangle CCW with positive area; returns the total area.
double checkCcw(const std::vector<Vec2>& p, const Triangles& tris) {
  double total = 0.0;
  for (const auto& t : tris) {
    const double a = signedArea(p, t);
    EXPECT_GT(a, 0.0) << "triangle " << t[0] << " " << t[1] << " " << t[2];
    total += a;
  }
  return total;
}

Vec2 centroid(const std::vector<Vec2>& p, const std::array<int, 3>& t) {
  return (p[t[0]] + p[t[1]] + p[t[2]]) / 3.0;
}

}  // namespace

TEST(ConstrainedDelaunay, SquareWithInteriorPoints) {
  std::vector<Vec2> p{{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0.3, 0.4}, {0.7, 0.6}, {0.5, 0.2}};
  Segments c;
  addLoop(c, {0, 1, 2, 3});
  const auto tris = constrainedDelaunay(p, c);
  // n_interior = 3, n_boundary = 4: 2*3 + 4 - 2 triangles.
  EXPECT_EQ(tris.size(), 8u);
  EXPECT_NEAR(checkCcw(p, tris), 1.0, 1e-14);
  std::set<int> used;
  for (const auto& t : tris) used.insert(t.begin(), t.end());
  EXPECT_EQ(used.size(), p.size()) << "every point is a vertex";
}

TEST(ConstrainedDelaunay, ConvexPolygonTriangleCount) {
  // A regular 12-gon with a ring of interior points: 2*n_int + n_bound - 2.
  std::vector<Vec2> p;
  const int nb = 12;
  for (int i = 0; i < nb; ++i) {
    const double a = 2.0 * std::numbers::pi * i / nb;
    p.emplace_back(std::cos(a), std::sin(a));
  }
  const int ni = 7;
  for (int i = 0; i < ni; ++i) {
    const double a = 2.0 * std::numbers::pi * (i + 0.3) / ni;
    p.emplace_back(0.5 * std::cos(a), 0.5 * std::sin(a) + 0.01 * i);
  }
  Segments c;
  std::vector<int> loop;
  for (int i = 0; i < nb; ++i) loop.push_back(i);
  addLoop(c, loop);
  const auto tris = constrainedDelaunay(p, c);
  EXPECT_EQ(static_cast<int>(tris.size()), 2 * ni + nb - 2);
  EXPECT_NEAR(checkCcw(p, tris), polygonArea(p, loop), 1e-13);
}

TEST(ConstrainedDelaunay, LShapeHasNoTriangleOutside) {
  // L: [0,2]x[0,1] union [0,1]x[1,2]; the notch (1,2]x(1,2] is outside.
  std::vector<Vec2> p{{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}, {0.5, 0.5}, {1.5, 0.5}};
  Segments c;
  const std::vector<int> loop{0, 1, 2, 3, 4, 5};
  addLoop(c, loop);
  const auto tris = constrainedDelaunay(p, c);
  EXPECT_NEAR(checkCcw(p, tris), 3.0, 1e-14);
  for (const auto& t : tris) {
    const Vec2 g = centroid(p, t);
    EXPECT_FALSE(g.x() > 1.0 && g.y() > 1.0) << "triangle in the notch";
  }
  // Without constraints nothing is enclosed.
  EXPECT_TRUE(constrainedDelaunay(p, {}).empty());
}

TEST(ConstrainedDelaunay, PolygonWithHole) {
  std::vector<Vec2> p{{0, 0}, {3, 0}, {3, 3}, {0, 3}, {1, 1}, {2, 1}, {2, 2}, {1, 2}};
  Segments c;
  addLoop(c, {0, 1, 2, 3});
  addLoop(c, {4, 7, 6, 5});  // the hole, clockwise (orientation must not matter)
  const auto tris = constrainedDelaunay(p, c);
  EXPECT_NEAR(checkCcw(p, tris), 9.0 - 1.0, 1e-14);
  for (const auto& t : tris) {
    const Vec2 g = centroid(p, t);
    EXPECT_FALSE(g.x() > 1.0 && g.x() < 2.0 && g.y() > 1.0 && g.y() < 2.0)
        << "triangle inside the hole";
  }
  // An island inside the hole (nesting level 3) is inside again.
  p.insert(p.end(), {{1.25, 1.25}, {1.75, 1.25}, {1.75, 1.75}, {1.25, 1.75}});
  addLoop(c, {8, 9, 10, 11});
  const auto withIsland = constrainedDelaunay(p, c);
  EXPECT_NEAR(checkCcw(p, withIsland), 8.0 + 0.25, 1e-14);
}

TEST(ConstrainedDelaunay, RespectsAConstraintDiagonal) {
  // A thin rhombus: Delaunay alone picks the short diagonal 1-3.
  std::vector<Vec2> p{{0, 0}, {1, -0.2}, {2, 0}, {1, 0.2}};
  Segments c;
  addLoop(c, {0, 1, 2, 3});
  const auto free = constrainedDelaunay(p, c);
  ASSERT_EQ(free.size(), 2u);
  EXPECT_TRUE(hasEdge(free, 1, 3));
  c.push_back({0, 2});
  const auto forced = constrainedDelaunay(p, c);
  ASSERT_EQ(forced.size(), 2u);
  EXPECT_TRUE(hasEdge(forced, 0, 2));
  EXPECT_FALSE(hasEdge(forced, 1, 3));
  EXPECT_NEAR(checkCcw(p, forced), 0.4, 1e-14);
}

TEST(ConstrainedDelaunay, RejectsIntersectionsAndDuplicates) {
  const std::vector<Vec2> p{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  Segments crossing;
  addLoop(crossing, {0, 1, 2, 3});
  crossing.push_back({0, 2});
  crossing.push_back({1, 3});
  EXPECT_THROW(constrainedDelaunay(p, crossing), std::invalid_argument);
  try {
    constrainedDelaunay(p, crossing);
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("crosses"), std::string::npos) << e.what();
  }

  // A constraint through another point.
  std::vector<Vec2> q = p;
  q.emplace_back(0.5, 0.5);
  Segments through;
  addLoop(through, {0, 1, 2, 3});
  through.push_back({0, 2});
  try {
    constrainedDelaunay(q, through);
    ADD_FAILURE() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("point 4"), std::string::npos) << e.what();
  }

  // Duplicates, exact and within 1e-12 relative.
  std::vector<Vec2> dup = p;
  dup.emplace_back(1.0, 1.0 + 1e-14);
  EXPECT_THROW(constrainedDelaunay(dup, {}), std::invalid_argument);
  dup.back() = Vec2(1.0, 1.0);
  EXPECT_THROW(constrainedDelaunay(dup, {}), std::invalid_argument);

  EXPECT_THROW(constrainedDelaunay(p, {{0, 4}}), std::invalid_argument);
  EXPECT_THROW(constrainedDelaunay(p, {{2, 2}}), std::invalid_argument);
}

TEST(ConstrainedDelaunay, DeterministicAndCanonical) {
  std::vector<Vec2> p;
  Segments c;
  // A grid of cocircular points (the ambiguous case for Delaunay).
  for (int j = 0; j <= 4; ++j)
    for (int i = 0; i <= 4; ++i) p.emplace_back(0.1 * i, 0.1 * j);
  addLoop(c, {0, 1, 2, 3, 4, 9, 14, 19, 24, 23, 22, 21, 20, 15, 10, 5});
  const auto a = constrainedDelaunay(p, c);
  const auto b = constrainedDelaunay(p, c);
  EXPECT_EQ(a, b);
  EXPECT_EQ(a.size(), 32u);
  EXPECT_TRUE(std::is_sorted(a.begin(), a.end()));
  for (const auto& t : a) EXPECT_TRUE(t[0] < t[1] && t[0] < t[2]);
  EXPECT_NEAR(checkCcw(p, a), 0.16, 1e-14);
}
