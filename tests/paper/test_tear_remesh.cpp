// Tearing S_G (thesis 3.3.3 "Remeshing", Figs. 3.20-3.23): the cut keeps S_G
// valid (validate), the lips are a slit of the kerf's width, S_P is built
// from the torn S_G, and curved regions the tear crosses become flat.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <map>
#include <optional>
#include <string>

#include "crumple/core/geometry2d.hpp"
#include "crumple/core/rng.hpp"
#include "crumple/paper/enrich.hpp"
#include "crumple/paper/geometric_step.hpp"
#include "crumple/paper/initial_sheet.hpp"
#include "crumple/paper/tear_remesh.hpp"

using namespace crumple;
using namespace crumple::paper;

namespace {

constexpr double kW = 0.2, kH = 0.1;

GeometricMesh flatSheet() {
  return makeFlatSheet(kW, kH, {Vec2(0, 0), Vec2(kW, 0), Vec2(kW, kH), Vec2(0, kH)}, Vec3::Zero(),
                       Vec3::UnitX(), Vec3::UnitY())
      .mesh;
}

// Boundary vertices of S_G within `d` of the segment [a, b].
int verticesNear(const GeometricMesh& g, const Vec2& a, const Vec2& b, double d) {
  int n = 0;
  for (const GeometricVertex& v : g.vertices)
    if (v.onBoundary && distanceToSegment(v.pattern, a, b) <= d) ++n;
  return n;
}

}  // namespace

// Case 3 (Fig. 3.23): a tear from the middle of the bottom edge into the one
// flat region. S_G stays valid, s_{t+1} is an outline corner, both lips are
// on the outline half a kerf from the centre line, the sheet's area shrinks
// by the slit's area only, and S_P builds on it with the slit open.
TEST(TearRemesh, CutIntoAFlatRegionKeepsSGValid) {
  GeometricMesh g = flatSheet();
  const double area = outlineArea(g);
  GeometricCutOptions options;
  const Vec2 from(0.1, 0.0), to(0.1, 0.04);
  const auto cut = cutGeometricMesh(g, from, to, options);
  ASSERT_TRUE(cut.has_value());
  EXPECT_EQ(validate(g), "");
  const GeometricVertex& tip = g.vertices[static_cast<std::size_t>(cut->tip)];
  EXPECT_TRUE(tip.corner);
  EXPECT_NEAR((tip.pattern - to).norm(), 0.0, 1e-12);
  // The slit: a V of width kerf at the outline, 0 at the tip.
  EXPECT_NEAR(area - outlineArea(g), 0.5 * options.kerf * 0.04, 1e-3 * options.kerf * 0.04);
  EXPECT_GE(verticesNear(g, Vec2(0.1 - options.kerf, 0.0), Vec2(0.1 + options.kerf, 0.0), 1e-12),
            2);
  EXPECT_EQ(g.outline.size(), 4u + 3u);  // two lip corners at the edge, the tip
  const PhysicalMesh sp = buildPhysicalMesh(g, CrumpleParams{});
  EXPECT_EQ(mesh::validate(sp.mesh), "");
  // No S_P triangle spans the slit: every triangle's centroid is off the centre line.
  for (const auto& t : sp.mesh.triangles) {
    const Vec2 c = (sp.mesh.pattern[static_cast<std::size_t>(t[0])] +
                    sp.mesh.pattern[static_cast<std::size_t>(t[1])] +
                    sp.mesh.pattern[static_cast<std::size_t>(t[2])]) /
                   3.0;
    EXPECT_GT(distanceToSegment(c, from, to), 0.25 * options.kerf);
  }
}

// The tear goes on from its tip and turns: s_t is split into two outline
// corners (Fig. 3.20), S_G stays valid, and the new tip is where the
// advance ends.
TEST(TearRemesh, TheTearGoesOnFromItsTipAndTurns) {
  GeometricMesh g = flatSheet();
  const auto first = cutGeometricMesh(g, Vec2(0.1, 0.0), Vec2(0.1, 0.03));
  ASSERT_TRUE(first.has_value());
  const auto second = cutGeometricMesh(g, Vec2(0.1, 0.03), Vec2(0.12, 0.05), {}, Vec2(0.0, 1.0));
  ASSERT_TRUE(second.has_value());
  EXPECT_EQ(validate(g), "");
  EXPECT_NEAR((g.vertices[static_cast<std::size_t>(second->tip)].pattern - Vec2(0.12, 0.05)).norm(),
              0.0, 1e-12);
  // Two copies of s_t, each within a kerf of it.
  int copies = 0;
  for (const GeometricVertex& v : g.vertices)
    if ((v.pattern - Vec2(0.1, 0.03)).norm() < 2e-5) ++copies;
  EXPECT_EQ(copies, 2);
  const PhysicalMesh sp = buildPhysicalMesh(g, CrumpleParams{});
  EXPECT_EQ(mesh::validate(sp.mesh), "");
}

// A tear that would reach the outline again (the sheet in two pieces) is
// refused and S_G left as it was.
TEST(TearRemesh, ACutThroughTheSheetIsRefused) {
  GeometricMesh g = flatSheet();
  const GeometricMesh before = g;
  EXPECT_FALSE(cutGeometricMesh(g, Vec2(0.1, 0.0), Vec2(0.1, 0.2)).has_value());
  EXPECT_EQ(g.faces, before.faces);
  EXPECT_EQ(g.vertices.size(), before.vertices.size());
}

// Cases 1-2 (Figs. 3.21-3.22): a curved region the tear crosses becomes
// flat triangles over the same vertices before the cut.
TEST(TearRemesh, ACurvedRegionTheTearCrossesBecomesFlat) {
  GeometricMesh g = flatSheet();
  // Rulings: a curved strip x in [0.05, 0.15] of vertical rulings.
  const auto boundaryVertex = [&](const Vec2& p) {
    GeometricVertex v;
    v.pattern = p;
    v.position = Vec3(p.x(), p.y(), 0.0);
    v.onBoundary = true;
    v.outlineSegment = p.y() == 0.0 ? 0 : 2;
    return addVertex(g, v);
  };
  const int a0 = boundaryVertex(Vec2(0.05, 0.0)), a1 = boundaryVertex(Vec2(0.05, kH));
  const int b0 = boundaryVertex(Vec2(0.15, 0.0)), b1 = boundaryVertex(Vec2(0.15, kH));
  g.faces.clear();
  g.regions.clear();
  Region left, strip, right;
  strip.type = mesh::RegionType::Curved;
  strip.rulings = {{a0, a1}, {b0, b1}};
  g.regions = {left, strip, right};
  const auto face = [&](std::array<int, 4> v, int r) {
    GeometricFace f;
    f.v = v;
    f.region = r;
    g.faces.push_back(f);
  };
  face({0, a0, a1, -1}, 0);
  face({0, a1, 3, -1}, 0);
  face({a0, b0, b1, a1}, 1);
  face({b0, 1, 2, -1}, 2);
  face({b0, 2, b1, -1}, 2);
  ASSERT_EQ(validate(g), "");
  const auto cut = cutGeometricMesh(g, Vec2(0.1, 0.0), Vec2(0.1, 0.05));
  ASSERT_TRUE(cut.has_value());
  EXPECT_EQ(cut->regionsFlattened, 1);
  EXPECT_EQ(g.regions[1].type, mesh::RegionType::Flat);
  EXPECT_EQ(validate(g), "");
  for (const GeometricFace& f : g.faces) EXPECT_EQ(f.size(), 3);
  const PhysicalMesh sp = buildPhysicalMesh(g, CrumpleParams{});
  EXPECT_EQ(mesh::validate(sp.mesh), "");
}

// Hard cases: 60 sheets, each torn by up to 6 advances in random directions
// and lengths from random outline points, then from the tips. Every cut
// either leaves a valid S_G on which S_P builds, or is refused (std::nullopt
// or std::invalid_argument) with S_G exactly as it was.
TEST(TearRemesh, RandomTearsKeepSGValidOrLeaveItUnchanged) {
  const CounterRng rng(7, 0, RngPurpose::Generic);
  std::uint64_t draw = 0;
  int made = 0, refused = 0;
  std::map<std::string, int> reasons;  // why cuts were refused (their text up to a number)
  for (int sheet = 0; sheet < 60; ++sheet) {
    GeometricMesh g = flatSheet();
    std::optional<Vec2> tip, direction;
    for (int step = 0; step < 6; ++step) {
      Vec2 from;
      if (tip) {
        from = *tip;
      } else {
        const double s = rng.uniform(draw++) * outlinePerimeter(g);
        from = outlinePoint(g, s);
      }
      const double angle = 2.0 * std::numbers::pi * rng.uniform(draw++);
      const double length = 0.002 + 0.03 * rng.uniform(draw++);
      const Vec2 to = from + length * Vec2(std::cos(angle), std::sin(angle));
      const GeometricMesh before = g;
      std::optional<GeometricCutResult> cut;
      try {
        cut = cutGeometricMesh(g, from, to, {}, tip ? direction : std::nullopt);
      } catch (const std::invalid_argument& e) {
        const std::string why = e.what();
        ++reasons[why.substr(0, why.find_first_of("0123456789"))];
        cut.reset();
      }
      if (!cut) {
        ++refused;
        EXPECT_EQ(g.faces, before.faces);
        EXPECT_EQ(g.vertices.size(), before.vertices.size());
        tip.reset();
        continue;
      }
      ++made;
      ASSERT_EQ(validate(g), "") << "sheet " << sheet << " step " << step;
      PhysicalMesh sp;
      ASSERT_NO_THROW(sp = buildPhysicalMesh(g, CrumpleParams{}))
          << "sheet " << sheet << " step " << step << " from " << from.transpose() << " to "
          << to.transpose() << " after " << direction.value_or(Vec2::Zero()).transpose();
      ASSERT_EQ(mesh::validate(sp.mesh), "") << "sheet " << sheet << " step " << step;
      direction = (cut->cut.back() - cut->cut.front()).normalized();
      tip = cut->cut.back();
    }
  }
  std::printf("[ measure ] random tears: %d cuts made, %d refused\n", made, refused);
  for (const auto& [why, n] : reasons) std::printf("[ measure ]   %d: %s\n", n, why.c_str());
  // Every refusal is one of the documented ones (no invalid S_G).
  for (const auto& [why, n] : reasons) EXPECT_EQ(why.find("after the cut"), std::string::npos) << why;
  EXPECT_GT(made, 100);
}
