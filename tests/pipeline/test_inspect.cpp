// The popping measure of `crumple inspect` (docs/CRUMPLING.md): the sheet's
// centroid and radius of gyration do not depend on how its surface is
// triangulated (so a re-meshed S_P that did not move measures 0), the
// measure is the jump over 3 x (handle motion + 1 mm), and a sheet that
// jumps while its handles stand still measures far above 1; and the
// bounding box `extent`.
#include <gtest/gtest.h>

#include <cmath>

#include "crumple/pipeline/inspect.hpp"

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
