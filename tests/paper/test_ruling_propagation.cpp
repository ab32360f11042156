// Ruling propagation and singular-vertex insertion (paper Sec. 5.1-5.2,
// Appendices A-B) on hand-made deformations of a 10 cm sheet.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>

#include "crumple/paper/geometric_step.hpp"
#include "crumple/paper/initial_sheet.hpp"

using namespace crumple;
using namespace crumple::paper;

namespace {

constexpr double kL = 0.10;

// Rolls pattern x around a cylinder of radius R whose axis is parallel to y.
Vec3 rollX(const Vec2& p, double radius) {
  const double a = (p.x() - 0.5 * kL) / radius;
  return Vec3(radius * std::sin(a), p.y(), radius * (1.0 - std::cos(a)));
}

void deform(GeometricMesh& g, const std::function<Vec3(const Vec2&)>& f) {
  for (GeometricVertex& v : g.vertices) v.position = f(v.pattern);
}

int countRegions(const GeometricMesh& g, mesh::RegionType type) {
  int n = 0;
  for (const Region& r : g.regions) n += r.type == type ? 1 : 0;
  return n;
}

int countSingular(const GeometricMesh& g) {
  int n = 0;
  for (const GeometricVertex& v : g.vertices) n += v.singular ? 1 : 0;
  return n;
}

// Consecutive ruling ends of every curved region are one vertex (a fan) or
// at least half the ruling spacing apart on both sides.
void expectRulingEndsApart(const GeometricMesh& g, const CrumpleParams& params) {
  const auto P = [&](int v) -> const Vec2& {
    return g.vertices[static_cast<std::size_t>(v)].pattern;
  };
  for (std::size_t c = 0; c < g.regions.size(); ++c) {
    const Region& region = g.regions[c];
    if (region.type != mesh::RegionType::Curved) continue;
    for (std::size_t k = 1; k < region.rulings.size(); ++k) {
      const Ruling& q = region.rulings[k - 1];
      const Ruling& r = region.rulings[k];
      for (const auto& [x, y] : {std::pair{q.a, r.a}, std::pair{q.b, r.b}}) {
        if (x == y) continue;
        EXPECT_GE((P(x) - P(y)).norm(), 0.5 / params.rhoBound - 1e-12)
            << "region " << c << ", rulings " << k - 1 << " and " << k;
      }
    }
  }
}

// A w x h sheet rolled around a cylinder of radius r whose axis runs through
// the sheet's centre at `tilt` from the pattern's y axis, its compression
// treated with the outline placed on the cylinder.
struct TreatedRoll {
  InitialSheet sheet;
  GeometricStepStats stats;
  Vec2 axis;  // pattern direction of the rulings
};

TreatedRoll treatTiltedRoll(double w, double h, double r, double tilt) {
  TreatedRoll out{makeFlatSheet(w, h, {}, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY()),
                  {},
                  Vec2(std::sin(tilt), std::cos(tilt))};
  const Vec2 axis = out.axis;
  const Vec2 across(axis.y(), -axis.x());
  const auto roll = [&](const Vec2& p) {
    const double u = (p - Vec2(0.5 * w, 0.5 * h)).dot(across);
    const double v = (p - Vec2(0.5 * w, 0.5 * h)).dot(axis);
    return Vec3(r * std::sin(u / r), v, r * (1.0 - std::cos(u / r)));
  };
  GeometricMesh& g = out.sheet.mesh;
  deform(g, roll);
  std::uint64_t draw = 0;
  const BoundaryPosition boundary = [&](double s) { return roll(outlinePoint(g, s)); };
  treatCompression(g, CrumpleParams{}, boundary, CounterRng(1, 0, RngPurpose::SingularityPlacement),
                   draw, out.stats);
  return out;
}

}  // namespace

TEST(RulingPropagation, UncompressedSheetIsLeftAlone) {
  InitialSheet sheet = makeFlatSheet(kL, kL, {}, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY());
  GeometricStepStats stats;
  std::uint64_t draw = 0;
  treatCompression(sheet.mesh, CrumpleParams{}, nullptr,
                   CounterRng(1, 0, RngPurpose::SingularityPlacement), draw, stats);
  EXPECT_EQ(stats.curvedCreated, 0);
  EXPECT_EQ(countRegions(sheet.mesh, mesh::RegionType::Curved), 0);
  EXPECT_EQ(sheet.mesh.faces.size(), 2u);
}

// Case c1 (paper Fig. 7): both borders on dS: the whole sheet becomes a
// curved region of rulings parallel to the cylinder axis.
TEST(RulingPropagation, CylinderWrapGivesParallelRulingsAlongTheAxis) {
  InitialSheet sheet = makeFlatSheet(kL, kL, {}, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY());
  GeometricMesh& g = sheet.mesh;
  deform(g, [](const Vec2& p) { return rollX(p, 0.04); });
  CrumpleParams params;
  GeometricStepStats stats;
  std::uint64_t draw = 0;
  const BoundaryPosition boundary = [&](double s) { return rollX(outlinePoint(g, s), 0.04); };
  treatCompression(g, params, boundary, CounterRng(1, 0, RngPurpose::SingularityPlacement), draw,
                   stats);
  ASSERT_EQ(validate(g), "");
  EXPECT_EQ(stats.curvedCreated, 1);
  EXPECT_EQ(countSingular(g), 0);
  int curved = -1;
  for (std::size_t r = 0; r < g.regions.size(); ++r) {
    if (g.regions[r].type == mesh::RegionType::Curved) curved = static_cast<int>(r);
  }
  ASSERT_GE(curved, 0);
  const Region& region = g.regions[static_cast<std::size_t>(curved)];
  // Rulings parallel to y in the pattern; spacing at most 1/rho_bound.
  double maxSpacing = 0.0;
  for (std::size_t k = 0; k < region.rulings.size(); ++k) {
    const Vec2 a = g.vertices[static_cast<std::size_t>(region.rulings[k].a)].pattern;
    const Vec2 b = g.vertices[static_cast<std::size_t>(region.rulings[k].b)].pattern;
    EXPECT_NEAR(a.x(), b.x(), 1e-9);
    if (k > 0) {
      const Vec2 a0 = g.vertices[static_cast<std::size_t>(region.rulings[k - 1].a)].pattern;
      maxSpacing = std::max(maxSpacing, (a - a0).norm());
    }
  }
  EXPECT_LE(maxSpacing, 1.0 / params.rhoBound + 1e-12);
  EXPECT_GE(region.rulings.size(), 12u);  // 10 cm at 1.2 /cm
  // The new boundary vertices lie on the cylinder (placed on the boundary curve).
  for (const GeometricVertex& v : g.vertices) {
    EXPECT_LT((v.position - rollX(v.pattern, 0.04)).norm(), 1e-12);
  }
  ::testing::Test::RecordProperty("rulings", static_cast<int>(region.rulings.size()));
}

// Case c2 (paper Fig. 8): a flat region next to an existing curved region,
// compressed across the curved region's rulings: a singular vertex appears
// inside the curved region and the new rulings are conical.
TEST(RulingPropagation, CompressionAcrossExistingRulingsInsertsASingularVertex) {
  CrumpleParams params;
  std::uint64_t draw = 0;
  // A sheet with vertices on the 4 cm line; its right part (x > 4 cm) is
  // rolled first, so a band of rulings along y forms there.
  InitialSheet s2 = makeFlatSheet(kL, kL, {Vec2(0.04, 0.0), Vec2(0.04, kL)}, Vec3::Zero(),
                                  Vec3::UnitX(), Vec3::UnitY());
  GeometricMesh& h = s2.mesh;
  for (int v : s2.handleVertices) h.vertices[static_cast<std::size_t>(v)].handle = false;
  const auto rollRight = [](const Vec2& p) {
    if (p.x() <= 0.04) return Vec3(p.x(), p.y(), 0.0);
    const double a = (p.x() - 0.04) / 0.05;
    return Vec3(0.04 + 0.05 * std::sin(a), p.y(), 0.05 * (1.0 - std::cos(a)));
  };
  deform(h, rollRight);
  GeometricStepStats st2;
  treatCompression(
      h, params, [&](double s) { return rollRight(outlinePoint(h, s)); },
      CounterRng(7, 0, RngPurpose::SingularityPlacement), draw, st2);
  ASSERT_EQ(validate(h), "");
  // The band covers the whole sheet at first; junction points then move to
  // the 4 cm line where the bending starts (paper Sec. 6.1).
  updateJunctions(h, params, nullptr, st2);
  ASSERT_EQ(validate(h), "");
  EXPECT_GE(st2.junctionMoves, 1);
  for (const Region& r : h.regions) {
    if (r.type != mesh::RegionType::Curved) continue;
    for (const Ruling& ruling : r.rulings) {
      EXPECT_GE(h.vertices[static_cast<std::size_t>(ruling.a)].pattern.x(),
                0.04 - 1.0 / params.rhoBound - 1e-9);
    }
  }
  ASSERT_EQ(countSingular(h), 0);
  ASSERT_GE(countRegions(h, mesh::RegionType::Curved), 1);
  // Then compress the flat left part along y.
  const auto both = [&](const Vec2& p) {
    const Vec3 base = rollRight(p);
    if (p.x() >= 0.04) return base;
    const double a = (p.y() - 0.5 * kL) / 0.03;
    const double w = (0.04 - p.x()) / 0.04;  // fades to zero at the border ruling
    return Vec3(base.x(),
                0.5 * kL + (0.03 * std::sin(a) - (p.y() - 0.5 * kL)) * w + (p.y() - 0.5 * kL),
                0.03 * (1.0 - std::cos(a)) * w);
  };
  deform(h, both);
  GeometricStepStats st3;
  treatCompression(
      h, params, [&](double s) { return both(outlinePoint(h, s)); },
      CounterRng(7, 0, RngPurpose::SingularityPlacement), draw, st3);
  ASSERT_EQ(validate(h), "");
  EXPECT_GE(st3.singularInserted, 1);
  EXPECT_GE(countSingular(h), 1);
  // Every region with an apex fans from a singular vertex.
  for (const Region& r : h.regions) {
    if (r.type != mesh::RegionType::Curved || r.apex < 0) continue;
    EXPECT_TRUE(h.vertices[static_cast<std::size_t>(r.apex)].singular);
    for (const Ruling& ruling : r.rulings) EXPECT_TRUE(ruling.a == r.apex || ruling.b == r.apex);
  }
  expectRulingEndsApart(h, params);
}

// Compression along a ruling of a curved region (our extension for the
// paper's Sec. 7.4 limitation): a d-cone appears on that ruling -- one
// singular vertex, fans of rulings from it, S_G still valid.
TEST(RulingPropagation, CompressedRulingGetsADCone) {
  InitialSheet sheet = makeFlatSheet(kL, kL, {}, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY());
  GeometricMesh& g = sheet.mesh;
  const auto roll = [](const Vec2& p) { return rollX(p, 0.04); };
  deform(g, roll);
  CrumpleParams params;
  GeometricStepStats stats;
  std::uint64_t draw = 0;
  const CounterRng rng(3, 0, RngPurpose::SingularityPlacement);
  treatCompression(
      g, params, [&](double s) { return roll(outlinePoint(g, s)); }, rng, draw, stats);
  ASSERT_EQ(countRegions(g, mesh::RegionType::Curved), 1);
  const Region band =
      g.regions.back().type == mesh::RegionType::Curved ? g.regions.back() : g.regions.front();
  ASSERT_GE(band.rulings.size(), 6u);
  // Shorten ruling 4 by 1 % in 3D (its b end slides towards its a end).
  const Ruling r = band.rulings[4];
  Vec3& xb = g.vertices[static_cast<std::size_t>(r.b)].position;
  const Vec3 xa = g.vertices[static_cast<std::size_t>(r.a)].position;
  xb = xa + 0.99 * (xb - xa);
  GeometricStepStats st;
  treatCurvedCompression(g, params, rng, draw, st);
  ASSERT_EQ(validate(g), "");
  EXPECT_EQ(st.singularInserted, 1);
  ASSERT_EQ(countSingular(g), 1);
  int s = -1;
  for (std::size_t v = 0; v < g.vertices.size(); ++v) {
    if (g.vertices[v].singular) s = static_cast<int>(v);
  }
  // Within half a ruling spacing of the compressed ruling's line (x = const).
  const double x = g.vertices[static_cast<std::size_t>(s)].pattern.x();
  EXPECT_LT(std::abs(x - g.vertices[static_cast<std::size_t>(r.a)].pattern.x()),
            0.5 / params.rhoBound + 1e-12);
  int fans = 0;
  for (const Region& region : g.regions) fans += region.apex == s ? 1 : 0;
  EXPECT_EQ(fans, 2);  // one fan per boundary chain (paper Fig. 11)
}

// paper Sec. 6.1, Fig. 12 right: a border ruling between a curved region and
// a flat region bent by more than theta_high moves its junction points one
// ruling spacing into the flat region.
TEST(RulingPropagation, JunctionMovesIntoTheFlatRegionAboveThetaHigh) {
  InitialSheet s2 = makeFlatSheet(kL, kL, {Vec2(0.04, 0.0), Vec2(0.04, kL)}, Vec3::Zero(),
                                  Vec3::UnitX(), Vec3::UnitY());
  GeometricMesh& h = s2.mesh;
  for (int v : s2.handleVertices) h.vertices[static_cast<std::size_t>(v)].handle = false;
  const auto rollRight = [](double from) {
    return [from](const Vec2& p) {
      if (p.x() <= from) return Vec3(p.x(), p.y(), 0.0);
      const double a = (p.x() - from) / 0.05;
      return Vec3(from + 0.05 * std::sin(a), p.y(), 0.05 * (1.0 - std::cos(a)));
    };
  };
  CrumpleParams params;
  std::uint64_t draw = 0;
  GeometricStepStats st;
  deform(h, rollRight(0.04));
  treatCompression(h, params, nullptr, CounterRng(7, 0, RngPurpose::SingularityPlacement), draw,
                   st);
  updateJunctions(h, params, nullptr, st);  // the band shrinks to x >= 4 cm
  ASSERT_EQ(validate(h), "");
  // Over all curved regions: how many rulings, and the smallest x any
  // ruling reaches (the border with the flat part x < 4 cm).
  const auto rulingCount = [&] {
    std::size_t n = 0;
    for (const Region& r : h.regions)
      n += r.type == mesh::RegionType::Curved ? r.rulings.size() : 0;
    return n;
  };
  const auto rulingSpan = [&] {  // extent in x of the curved band's rulings
    double lo = 1.0, hi = -1.0;
    for (const Region& r : h.regions) {
      for (const Ruling& ruling : r.rulings) {
        const double x = h.vertices[static_cast<std::size_t>(ruling.a)].pattern.x();
        lo = std::min(lo, x);
        hi = std::max(hi, x);
      }
    }
    return std::make_pair(lo, hi);
  };
  ASSERT_GE(countRegions(h, mesh::RegionType::Curved), 1);
  const std::size_t before = rulingCount();
  const auto [xBefore, xHiBefore] = rulingSpan();
  // The flat part turns by 0.05 rad about the band's border ruling (x =
  // xBefore; the band keeps its shape).
  deform(h, [&](const Vec2& p) {
    const Vec3 x = rollRight(0.04)(p);
    if (p.x() >= xBefore) return x;
    const double a = -0.05;
    return Vec3(xBefore - (xBefore - p.x()) * std::cos(a), p.y(), (xBefore - p.x()) * std::sin(a));
  });
  GeometricStepStats st2;
  updateJunctions(h, params, nullptr, st2);
  ASSERT_EQ(validate(h), "");
  EXPECT_EQ(st2.junctionMoves, 1);
  EXPECT_EQ(rulingCount(), before + 1);
  // One end moved by about one ruling spacing, onto the next boundary vertex
  // when that is within 1.5 spacings (the first eligible end: both border
  // flat parts bent against the band qualify).
  const auto [xAfter, xHiAfter] = rulingSpan();
  const double grown = (xHiAfter - xAfter) - (xHiBefore - xBefore);
  EXPECT_GT(grown, 0.5 / params.rhoBound);
  EXPECT_LE(grown, 1.5 / params.rhoBound + 1e-12);
}

// A long strip rolled about an axis 3 degrees off its short side (the
// moebius sample's first bend): the strip of chords ends in thin wedges at
// the corners. No ruling may run along the outline, and consecutive ruling
// ends are either one vertex (a fan) or at least half the ruling spacing
// apart: ends millimetres apart made sliver cells that stalled the elastic
// solve.
TEST(RulingPropagation, TiltedRollOfAStripKeepsRulingEndsApart) {
  constexpr double kW = 0.24, kH = 0.03, kR = 0.05;
  const TreatedRoll rolled = treatTiltedRoll(kW, kH, kR, 3.0 * std::numbers::pi / 180.0);
  const GeometricMesh& g = rolled.sheet.mesh;
  const GeometricStepStats& stats = rolled.stats;
  const CrumpleParams params;
  ASSERT_EQ(validate(g), "");
  ASSERT_GE(stats.curvedCreated, 1);
  EXPECT_EQ(countSingular(g), 0);
  expectRulingEndsApart(g, params);
  for (const Region& region : g.regions) {
    if (region.type != mesh::RegionType::Curved) continue;
    for (std::size_t k = 0; k < region.rulings.size(); ++k) {
      const Ruling& r = region.rulings[k];
      const GeometricVertex& a = g.vertices[static_cast<std::size_t>(r.a)];
      const GeometricVertex& b = g.vertices[static_cast<std::size_t>(r.b)];
      // Along a short side of the outline only as that whole side (the
      // strip's limit), never along a piece of it.
      if (std::abs(a.pattern.x() - b.pattern.x()) < 1e-12 &&
          (a.pattern.x() < 1e-12 || a.pattern.x() > kW - 1e-12)) {
        EXPECT_TRUE(a.corner && b.corner) << "ruling " << k << " runs along part of a short side";
      }
    }
  }
}

// A strip whose rulings run past a corner of the sheet (paper Appendix B):
// the corner lies between two consecutive ruling ends on one border, so a
// cell between them would have five sides. The cell is split by a ruling
// through the corner and the roll still becomes a curved region, whatever the
// tilt (the strip was declined, and the sheet stayed one flat region while
// its S_P bent: docs/CRUMPLING.md "The flap was a declined strip").
TEST(RulingPropagation, RollPastASheetCornerSplitsTheCellAtTheCorner) {
  for (int step = 0; step <= 40; ++step) {
    const double degrees = 2.0 + 0.5 * step;
    const TreatedRoll rolled = treatTiltedRoll(kL, kL, 0.04, degrees * std::numbers::pi / 180.0);
    const GeometricMesh& g = rolled.sheet.mesh;
    const GeometricStepStats& stats = rolled.stats;
    const Vec2& axis = rolled.axis;
    ASSERT_EQ(validate(g), "") << degrees << " degrees";
    EXPECT_GE(stats.curvedCreated, 1) << degrees << " degrees";
    EXPECT_EQ(countSingular(g), 0) << degrees << " degrees";
    // Every ruling lies along the roll's axis within the spread a ruling
    // through a corner takes (it joins the corner to an end of its
    // neighbour), and its 3D length is its pattern length (a straight line
    // on the cylinder).
    for (const Region& region : g.regions) {
      if (region.type != mesh::RegionType::Curved) continue;
      for (const Ruling& r : region.rulings) {
        const GeometricVertex& a = g.vertices[static_cast<std::size_t>(r.a)];
        const GeometricVertex& b = g.vertices[static_cast<std::size_t>(r.b)];
        const Vec2 d = (b.pattern - a.pattern).normalized();
        EXPECT_GT(std::abs(d.dot(axis)), std::cos(20.0 * std::numbers::pi / 180.0))
            << degrees << " degrees";
      }
    }
  }
}
