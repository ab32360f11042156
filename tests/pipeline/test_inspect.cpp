// The popping measure of `crumple inspect` (docs/CRUMPLING.md): the sheet's
// centroid and radius of gyration do not depend on how its surface is
// triangulated (so a re-meshed S_P that did not move measures 0), the
// measure is the jump over 3 x (handle motion + 1 mm), and a sheet that
// jumps while its handles stand still measures far above 1; and the
// bounding box `extent`; and how far the sheet passes into itself.
#include <gtest/gtest.h>

#include <cmath>

#include "crumple/pipeline/inspect.hpp"
#include "crumple/pipeline/shape_compare.hpp"

using namespace crumple;

namespace {

// A 10 x 10 cm square folded 90 degrees along x = 5 cm, triangulated
// either as four right triangles or with a vertex at each half's centre.
cache::FrameRecord foldedSquare(bool fine, const Vec3& offset) {
  cache::FrameRecord f;
  const auto place = [&](double x, double y) {
    f.pattern.emplace_back(x, y);
    f.positions.push_back(x <= 0.05 ? Vec3(x, y, 0.0) + offset : Vec3(0.05, y, x - 0.05) + offset);
    return static_cast<int>(f.pattern.size()) - 1;
  };
  const int a = place(0, 0), b = place(0.05, 0), c = place(0.1, 0);
  const int d = place(0, 0.1), e = place(0.05, 0.1), g = place(0.1, 0.1);
  if (!fine) {
    f.triangles = {{a, b, e}, {a, e, d}, {b, c, g}, {b, g, e}};
  } else {
    const int m = place(0.025, 0.05), n = place(0.075, 0.05);
    f.triangles = {{a, b, m}, {b, e, m}, {e, d, m}, {d, a, m},
                   {b, c, n}, {c, g, n}, {g, e, n}, {e, b, n}};
  }
  f.handleVertices = {a};
  f.handleTargets = {f.positions[static_cast<std::size_t>(a)]};
  return f;
}

}  // namespace

TEST(Inspect, SheetMomentsDoNotDependOnTheTriangulation) {
  const cache::FrameRecord coarse = foldedSquare(false, Vec3::Zero());
  const cache::FrameRecord fine = foldedSquare(true, Vec3::Zero());
  const auto a = pipeline::sheetMoments(coarse.triangles, coarse.pattern, coarse.positions);
  const auto b = pipeline::sheetMoments(fine.triangles, fine.pattern, fine.positions);
  // The folded square's centroid: each half's centre, averaged.
  EXPECT_NEAR((a.centroid - Vec3(0.0375, 0.05, 0.0125)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((b.centroid - a.centroid).norm(), 0.0, 1e-12);
  EXPECT_NEAR(b.gyration, a.gyration, 1e-12);
  EXPECT_GT(a.gyration, 0.03);
  EXPECT_NEAR(pipeline::poppingMeasure(coarse, fine), 0.0, 1e-9);
}

TEST(Inspect, PoppingIsTheJumpOverTheHandlesMotion) {
  const cache::FrameRecord before = foldedSquare(false, Vec3::Zero());
  // Carried 1 cm by its handle: 1 cm / (3 x (1 cm + 1 mm)).
  const cache::FrameRecord carried = foldedSquare(true, Vec3(0.01, 0.0, 0.0));
  EXPECT_NEAR(pipeline::poppingMeasure(before, carried), 0.01 / (3.0 * 0.011), 1e-9);
  // A 13 mm jump while the handle stands still: 13 / 3.
  cache::FrameRecord jumped = foldedSquare(true, Vec3(0.0, 0.013, 0.0));
  jumped.handleTargets = before.handleTargets;
  EXPECT_NEAR(pipeline::poppingMeasure(before, jumped), 0.013 / 0.003, 1e-9);
  // The same mass spread wider about the same centroid also counts.
  cache::FrameRecord spread = before;
  for (Vec3& x : spread.positions)
    x = 1.1 * (x - Vec3(0.0375, 0.05, 0.0125)) + Vec3(0.0375, 0.05, 0.0125);
  const auto a = pipeline::sheetMoments(before.triangles, before.pattern, before.positions);
  EXPECT_NEAR(pipeline::poppingMeasure(before, spread), 0.1 * a.gyration / 0.003, 1e-9);
}

// The sheet's bounding box (`extent`, e.g. how small a crumpled ball got):
// the folded square spans 5 cm in x, 10 cm in y and 5 cm in z.
TEST(Inspect, ExtentIsTheSheetsBoundingBox) {
  const cache::FrameRecord folded = foldedSquare(false, Vec3(1.0, 2.0, 3.0));
  const auto m = pipeline::measureFrame(folded);
  EXPECT_NEAR((m.extent - Vec3(0.05, 0.1, 0.05)).norm(), 0.0, 1e-12);
}

// `crumple compare A.pcache B.pcache` (pipeline/shape_compare.hpp): the
// distance between two sheets at the same pattern position does not depend
// on their triangulations, measures a rigid shift exactly, and sees the
// chords of a coarse mesh on a curved surface.
TEST(Inspect, SelfPenetrationCountsEdgesThroughAnotherLayer) {
  // The fine square folded flat (180 degrees), its right half 1 mm over
  // the left: two layers, no contact.
  cache::FrameRecord f = foldedSquare(true, Vec3::Zero());
  for (std::size_t v = 0; v < f.pattern.size(); ++v) {
    const double u = f.pattern[v].x() - 0.05;
    if (u > 0.0) f.positions[v] = Vec3(0.05 - u, f.pattern[v].y(), 0.001);
  }
  constexpr double kThickness = 1e-4;
  const auto apart = pipeline::selfPenetration(f, kThickness);
  EXPECT_EQ(apart.crossings, 0u);
  EXPECT_EQ(apart.depth, 0.0);
  // The right half's centre pushed 3 mm under the left half: its edges to
  // the two far corners pass through it, 1 mm (10 thicknesses) past it, and
  // two edges of the left half through the tilted right half.
  f.positions[7] = Vec3(0.03, 0.05, -0.003);
  const auto through = pipeline::selfPenetration(f, kThickness);
  EXPECT_EQ(through.crossings, 4u);
  EXPECT_NEAR(through.depth, 11.0, 1e-9);
  // The right half laid 0.04 mm over the left (0.4 thicknesses): layers in
  // contact, none through.
  for (std::size_t v = 0; v < f.pattern.size(); ++v)
    if (f.pattern[v].x() > 0.05) f.positions[v].z() = 4e-5;
  f.positions[7] = Vec3(0.025, 0.05, 4e-5);
  const auto touching = pipeline::selfPenetration(f, kThickness);
  EXPECT_EQ(touching.crossings, 0u);
  EXPECT_NEAR(touching.depth, 0.6, 1e-5);
}

TEST(ShapeCompare, TheSameSurfaceOnTwoMeshesMeasuresZero) {
  const cache::FrameRecord coarse = foldedSquare(false, Vec3::Zero());
  const cache::FrameRecord fine = foldedSquare(true, Vec3::Zero());
  const auto d = pipeline::shapeDistance(coarse.pattern, coarse.triangles, coarse.positions,
                                         fine.pattern, fine.triangles, fine.positions);
  EXPECT_NEAR(d.mean, 0.0, 1e-12);
  EXPECT_NEAR(d.max, 0.0, 1e-12);
  EXPECT_EQ(d.outside, 0u);
}

TEST(ShapeCompare, AShiftedSheetMeasuresItsShift) {
  const cache::FrameRecord a = foldedSquare(false, Vec3::Zero());
  const cache::FrameRecord b = foldedSquare(true, Vec3(0.0, 0.003, 0.004));
  const auto d = pipeline::shapeDistance(a.pattern, a.triangles, a.positions, b.pattern,
                                         b.triangles, b.positions);
  EXPECT_NEAR(d.mean, 0.005, 1e-12);
  EXPECT_NEAR(d.max, 0.005, 1e-12);
}

namespace {

// A w x h grid of n x m squares (each split in two), rolled onto a cylinder
// of radius r about the y axis (an isometry of the pattern).
cache::FrameRecord rolledGrid(int n, int m, double w, double h, double r) {
  cache::FrameRecord f;
  for (int j = 0; j <= m; ++j)
    for (int i = 0; i <= n; ++i) {
      const double x = w * i / n, y = h * j / m;
      f.pattern.emplace_back(x, y);
      f.positions.emplace_back(r * std::sin(x / r), y, r - r * std::cos(x / r));
    }
  const auto at = [&](int i, int j) { return j * (n + 1) + i; };
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < n; ++i) {
      f.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      f.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return f;
}

}  // namespace

TEST(ShapeCompare, ACoarseMeshOnACylinderIsOffByItsChordsSagitta) {
  const double r = 0.03;
  const cache::FrameRecord coarse = rolledGrid(4, 2, 0.1, 0.1, r);
  const cache::FrameRecord fine = rolledGrid(64, 2, 0.1, 0.1, r);
  const auto d = pipeline::shapeDistance(coarse.pattern, coarse.triangles, coarse.positions,
                                         fine.pattern, fine.triangles, fine.positions);
  // The coarse chords span 2.5 cm of arc: their sagitta r (1 - cos(h / 2r)).
  const double sagitta = r * (1.0 - std::cos(0.025 / (2.0 * r)));
  EXPECT_GT(d.mean, 0.2 * sagitta);
  EXPECT_LT(d.mean, sagitta);
  EXPECT_NEAR(d.max, sagitta, 0.05 * sagitta);
}

TEST(ShapeCompare, PointsOutsideTheOtherSheetAreCounted) {
  const cache::FrameRecord big = rolledGrid(4, 4, 0.1, 0.1, 1e3);
  const cache::FrameRecord small = rolledGrid(4, 4, 0.08, 0.1, 1e3);
  const auto d = pipeline::shapeDistance(big.pattern, big.triangles, big.positions, small.pattern,
                                         small.triangles, small.positions);
  EXPECT_EQ(d.outside, 5u);  // big's column at x = 10 cm lies beyond small's outline
  EXPECT_THROW(pipeline::shapeDistance(big.pattern, {}, big.positions, small.pattern,
                                       small.triangles, small.positions),
               std::invalid_argument);
}
