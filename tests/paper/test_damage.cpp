#include <gtest/gtest.h>

#include <numbers>

#include "crumple/paper/damage.hpp"

using namespace crumple;
using namespace crumple::paper;

// A fan of 6 triangles around vertex 0 (the singular vertex), plus one
// triangle away from it: rest angles and stiffness follow thesis eqs. 2.1-2.2.
TEST(FiberDamage, RestAngleAndWeakeningAroundASingularVertex) {
  mesh::SheetMesh m;
  m.pattern.push_back(Vec2::Zero());
  for (int k = 0; k < 6; ++k) {
    const double a = k * std::numbers::pi / 3.0;
    m.pattern.emplace_back(std::cos(a), std::sin(a));
  }
  m.pattern.emplace_back(2.0, 0.9);  // vertex 7 beyond edge (1, 2)
  for (int k = 0; k < 6; ++k) m.triangles.push_back({0, 1 + k, 1 + (k + 1) % 6});
  m.triangles.push_back({1, 7, 2});
  m.positions.resize(m.pattern.size(), Vec3::Zero());
  m.regionOfTriangle.assign(m.triangles.size(), 0);
  m.regionTypes = {mesh::RegionType::Flat};
  std::vector<mesh::MeshEdge> hinges;
  for (const auto& e : mesh::buildEdges(m)) {
    if (e.interior()) hinges.push_back(e);
  }
  std::vector<char> singular(m.pattern.size(), 0);
  singular[0] = 1;
  std::vector<double> angles(hinges.size(), 0.2);
  angles[0] = -0.1;  // a hinge folded the other way keeps its sign
  CrumpleParams params;
  const auto damage = fiberDamage(m, hinges, singular, angles, params);
  ASSERT_EQ(damage.size(), hinges.size());
  const double n0 = 6.0;  // edges around the singular vertex
  for (std::size_t h = 0; h < hinges.size(); ++h) {
    const bool touches = hinges[h].v[0] == 0 || hinges[h].v[1] == 0;
    if (touches) {
      EXPECT_NEAR(std::abs(damage[h].restAngle), std::numbers::pi / 8.0 / n0, 1e-15);
      EXPECT_NEAR(damage[h].stiffnessFactor, 1.0 / (1.0 + 10.0 / n0), 1e-15);
      EXPECT_EQ(damage[h].restAngle < 0.0, angles[h] < 0.0);
    } else {
      EXPECT_EQ(damage[h].restAngle, 0.0);
      EXPECT_EQ(damage[h].stiffnessFactor, 1.0);
    }
  }
  // Two singular vertices on one edge add up ("marked more than others").
  singular[1] = 1;
  const auto both = fiberDamage(m, hinges, singular, angles, params);
  for (std::size_t h = 0; h < hinges.size(); ++h) {
    if ((hinges[h].v[0] == 0 && hinges[h].v[1] == 1)) {
      EXPECT_GT(std::abs(both[h].restAngle), std::abs(damage[h].restAngle));
      EXPECT_LT(both[h].stiffnessFactor, damage[h].stiffnessFactor);
    }
  }
}
