// Sound events and resonators (thesis 4.3.2): curvature sign changes on the
// grid, friction components, tear tips, and the regions they set vibrating.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>

#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/sound/events.hpp"

namespace crumple::sound {
namespace {

// A W x H sheet placed by `place` (pattern -> world).
mesh::SheetMesh sheetAs(double w, double h, double edge,
                        const std::function<Vec3(const Vec2&)>& place) {
  mesh::SheetMesh m = mesh::makeRectangleSheet(w, h, edge);
  m.positions.clear();
  for (const Vec2& p : m.pattern) m.positions.push_back(place(p));
  return m;
}

// Bent about an axis along v into a cylinder of signed radius r: curvature
// 1/r across u (positive r bulges towards +z, the front side).
Vec3 bent(const Vec2& p, double w, double r) {
  const double s = p.x() - 0.5 * w;
  const double a = s / r;
  return {r * std::sin(a), p.y(), r * (1.0 - std::cos(a))};
}

SheetFrame frameOf(const mesh::SheetMesh& m) {
  SheetFrame f;
  f.mesh = &m;
  f.frameDuration = 1.0 / 24.0;
  return f;
}

int countKind(const std::vector<SoundEvent>& events, EventKind kind) {
  int n = 0;
  for (const auto& e : events) n += e.kind == kind;
  return n;
}

TEST(SoundEvents, TheGridMeasuresACylindersMeanCurvature) {
  const double w = 0.2, h = 0.15, r = 0.1;
  const auto m = sheetAs(w, h, 0.005, [&](const Vec2& p) { return bent(p, w, r); });
  EventDetector detector;
  (void)detector.detect(frameOf(m));
  int defined = 0;
  for (const auto& hv : detector.curvature()) {
    if (!hv) continue;
    ++defined;
    // H = 1 / (2 r) on a cylinder; the piecewise-flat mesh and the grid's
    // differences keep it within 5 %. Its sign follows the front side.
    EXPECT_NEAR(*hv, 0.5 / r, 0.05 * 0.5 / r);
  }
  EXPECT_GT(defined, 100);
}

TEST(SoundEvents, ACurvatureFlipIsOneCrumplingEventAndStillnessIsNone) {
  const double w = 0.2, h = 0.15, r = 0.1;
  const auto up = sheetAs(w, h, 0.005, [&](const Vec2& p) { return bent(p, w, r); });
  const auto down = sheetAs(w, h, 0.005, [&](const Vec2& p) { return bent(p, w, -r); });
  EventDetector detector;
  EXPECT_TRUE(detector.detect(frameOf(up)).empty());  // no previous curvature
  EXPECT_TRUE(detector.detect(frameOf(up)).empty());  // nothing changed
  const auto events = detector.detect(frameOf(down));
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, EventKind::Crumpling);
  // The sum of |dH| (1 / r) times the cells' area over the grid's interior
  // points (all but its outer ring, 1 cm apart).
  const double interior = (w - 0.01) * (h - 0.01);
  EXPECT_NEAR(events[0].amplitude, interior / r, 0.05 * interior / r);
  // A flip smaller than the threshold (3 / m) is no event: r = 0.5 m
  // gives |dH| = 2 / m.
  EventDetector gentle;
  (void)gentle.detect(
      frameOf(sheetAs(w, h, 0.005, [&](const Vec2& p) { return bent(p, w, 0.5); })));
  EXPECT_TRUE(
      gentle.detect(frameOf(sheetAs(w, h, 0.005, [&](const Vec2& p) { return bent(p, w, -0.5); })))
          .empty());
}

TEST(SoundEvents, AFreeCurvedBorderMakesAFlapResonatorAndAFlatSheetAClac) {
  const double w = 0.2, h = 0.15;
  EventParams params;
  // Bent across u: its two u-long borders (v = 0 and v = h) are arcs.
  const auto curved = sheetAs(w, h, 0.005, [&](const Vec2& p) { return bent(p, w, 0.1); });
  std::vector<int> all(curved.triangleCount());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  const std::vector<char> none(curved.vertexCount(), 0);
  auto res = findResonators(frameOf(curved), all, none, params);
  ASSERT_EQ(res.size(), 1u);
  // The polyline of the arc is the chord sum: 2 w within the mesh's error.
  EXPECT_NEAR(res[0].border, 2.0 * w, 0.01 * w);
  EXPECT_NEAR(res[0].ruling, h, 0.02 * h);  // 2 area / l_c: the straight rulings' length
  EXPECT_NEAR(res[0].area, w * h, 1e-3 * w * h);
  EXPECT_NEAR(res[0].radius, std::sqrt(w * h / std::numbers::pi), 1e-3);
  EXPECT_FALSE(res[0].constrained());

  const auto flat = sheetAs(w, h, 0.005, [](const Vec2& p) { return Vec3(p.x(), p.y(), 0.0); });
  res = findResonators(frameOf(flat), all, none, params);
  ASSERT_EQ(res.size(), 1u);
  EXPECT_TRUE(res[0].constrained());
  EXPECT_NEAR(res[0].ruling, std::sqrt(w * h), 1e-9);
  EXPECT_NEAR(res[0].normal.z(), 1.0, 1e-12);

  // Held along its borders, a curved sheet has no free border left.
  std::vector<char> held(curved.vertexCount(), 0);
  for (std::size_t v = 0; v < curved.vertexCount(); ++v)
    held[v] = curved.pattern[v].y() < 1e-9 || curved.pattern[v].y() > h - 1e-9;
  const SheetFrame f = frameOf(curved);
  std::vector<int> middle;
  for (std::size_t i = 0; i < curved.triangleCount(); ++i) {
    Vec2 c = Vec2::Zero();
    for (int v : curved.triangles[i]) c += curved.pattern[static_cast<std::size_t>(v)] / 3.0;
    if (std::abs(c.y() - 0.5 * h) < 0.01) middle.push_back(static_cast<int>(i));
  }
  res = findResonators(f, middle, held, params);
  ASSERT_EQ(res.size(), 1u);
  EXPECT_TRUE(res[0].constrained());
}

TEST(SoundEvents, ARidgeSteeperThanAMaxStopsTheResonator) {
  const double w = 0.2, h = 0.1;
  // Folded along u = w / 2 by `angle`: the right half turns about the fold.
  const auto folded = [&](double angle) {
    return sheetAs(w, h, 0.01, [&, angle](const Vec2& p) {
      const double s = p.x() - 0.5 * w;
      if (s <= 0.0) return Vec3(p.x(), p.y(), 0.0);
      return Vec3(0.5 * w + s * std::cos(angle), p.y(), s * std::sin(angle));
    });
  };
  EventParams params;  // a_max = 0.5 rad
  for (const double angle : {0.3, 0.8}) {
    const auto m = folded(angle);
    std::vector<int> left;
    for (std::size_t i = 0; i < m.triangleCount(); ++i) {
      double u = 0.0;
      for (int v : m.triangles[i]) u += m.pattern[static_cast<std::size_t>(v)].x() / 3.0;
      if (u < 0.25 * w) left.push_back(static_cast<int>(i));
    }
    const auto res =
        findResonators(frameOf(m), left, std::vector<char>(m.vertexCount(), 0), params);
    ASSERT_EQ(res.size(), 1u);
    const double expected = angle < params.maxDihedral ? w * h : 0.5 * w * h;
    EXPECT_NEAR(res[0].area, expected, 1e-6) << "fold " << angle;
  }
}

TEST(SoundEvents, ResonatorsSplitByRegionAndTakeTheirRulingsLength) {
  const double w = 0.2, h = 0.1;
  auto m = sheetAs(w, h, 0.01, [&](const Vec2& p) { return bent(p, w, 0.15); });
  // Two regions: the left half flat-typed, the right half curved.
  m.regionTypes = {mesh::RegionType::Flat, mesh::RegionType::Curved};
  m.regionOfTriangle.clear();
  for (const auto& t : m.triangles) {
    double u = 0.0;
    for (int v : t) u += m.pattern[static_cast<std::size_t>(v)].x() / 3.0;
    m.regionOfTriangle.push_back(u < 0.5 * w ? 0 : 1);
  }
  SheetFrame f = frameOf(m);
  // Rulings across the right half, from v = 0 to v = h (vertex pairs).
  for (std::size_t a = 0; a < m.vertexCount(); ++a)
    for (std::size_t b = 0; b < m.vertexCount(); ++b)
      if (m.pattern[a].x() > 0.5 * w + 1e-9 &&
          std::abs(m.pattern[a].x() - m.pattern[b].x()) < 1e-12 && m.pattern[a].y() < 1e-12 &&
          m.pattern[b].y() > h - 1e-12)
        f.rulings.push_back({static_cast<int>(a), static_cast<int>(b)});
  ASSERT_FALSE(f.rulings.empty());
  std::vector<int> all(m.triangleCount());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  const auto res = findResonators(f, all, std::vector<char>(m.vertexCount(), 0), EventParams{});
  ASSERT_EQ(res.size(), 2u);  // one per region, in region order
  EXPECT_NEAR(res[0].area, 0.5 * w * h, 1e-3 * w * h);
  EXPECT_NEAR(res[1].ruling, h, 1e-9);  // the rulings' own length
  // Its arcs are free borders, its straight end (a ruling) is not.
  EXPECT_NEAR(res[1].border, w, 0.01 * w);
}

TEST(SoundEvents, FrictionEventsAreTheTouchingComponentsWithTheirMeanSpeed) {
  const double w = 0.2, h = 0.1;
  const auto m = sheetAs(w, h, 0.01, [](const Vec2& p) { return Vec3(p.x(), 0.0, p.y()); });
  SheetFrame f = frameOf(m);
  double left = 0.0, right = 0.0;
  int nl = 0, nr = 0;
  for (std::size_t v = 0; v < m.vertexCount(); ++v) {
    const double u = m.pattern[v].x();
    if (u < 0.05) {
      const double speed = 0.05 + 0.1 * u;
      f.contacts.push_back({static_cast<int>(v), speed});
      left += speed;
      ++nl;
    } else if (u > 0.15) {
      f.contacts.push_back({static_cast<int>(v), 0.2});
      right += 0.2;
      ++nr;
    }
  }
  EventDetector detector;
  auto events = detector.detect(f);
  ASSERT_EQ(countKind(events, EventKind::Friction), 2);
  EXPECT_NEAR(events[0].amplitude, left / nl, 1e-12);
  EXPECT_NEAR(events[1].amplitude, right / nr, 1e-12);
  for (const auto& e : events) {
    ASSERT_FALSE(e.resonators.empty());
    EXPECT_TRUE(e.resonators[0].constrained());  // flat on the table
  }
  // Creeping slower than the minimum slide speed makes no sound.
  for (auto& c : f.contacts) c.slideSpeed = 0.5 * EventParams{}.minSlideSpeed;
  EXPECT_EQ(countKind(detector.detect(f), EventKind::Friction), 0);
}

TEST(SoundEvents, ATearTipThatAdvancedIsATearingEventAtItsSpeed) {
  const double w = 0.1, h = 0.1;
  const auto m = sheetAs(w, h, 0.01, [](const Vec2& p) { return Vec3(p.x(), p.y(), 0.02); });
  SheetFrame f = frameOf(m);
  f.tearAdvances.push_back({3, Vec2(0.05, 0.1), Vec2(0.05, 0.097)});
  f.tearAdvances.push_back({3, Vec2(0.05, 0.097), Vec2(0.05, 0.095)});
  EventDetector detector;
  const auto events = detector.detect(f);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, EventKind::Tearing);
  EXPECT_EQ(events[0].tear, 3);
  EXPECT_NEAR(events[0].amplitude, 0.005 * 24.0, 1e-12);
  EXPECT_LT((events[0].position - Vec3(0.05, 0.095, 0.02)).norm(), 1e-12);
  EXPECT_NEAR(events[0].duration, 1.0 / 24.0, 1e-15);
  // Its next advance, 6 frames later: the tear ran on between them.
  f.time += 6.0 / 24.0;
  f.tearAdvances = {{3, Vec2(0.05, 0.095), Vec2(0.05, 0.09)}};
  auto next = detector.detect(f);
  ASSERT_EQ(next.size(), 1u);
  EXPECT_NEAR(next[0].duration, 0.25, 1e-12);
  EXPECT_NEAR(next[0].amplitude, 0.005 / 0.25, 1e-12);
  // After a pause longer than maxTearGap (0.5 s) it counts 0.5 s only.
  f.time += 2.0;
  next = detector.detect(f);
  EXPECT_NEAR(next[0].duration, 0.5, 1e-12);
}

TEST(SoundEvents, DetectionIsDeterministicAndRefusesBadInput) {
  const double w = 0.2, h = 0.15;
  const auto a = sheetAs(w, h, 0.005, [&](const Vec2& p) { return bent(p, w, 0.1); });
  const auto b = sheetAs(w, h, 0.005, [&](const Vec2& p) { return bent(p, w, -0.12); });
  EventDetector one, two;
  (void)one.detect(frameOf(a));
  (void)two.detect(frameOf(a));
  const auto e1 = one.detect(frameOf(b));
  const auto e2 = two.detect(frameOf(b));
  ASSERT_EQ(e1.size(), e2.size());
  for (std::size_t i = 0; i < e1.size(); ++i) {
    EXPECT_EQ(e1[i].amplitude, e2[i].amplitude);
    EXPECT_EQ(e1[i].position, e2[i].position);
  }
  EXPECT_THROW(EventDetector(EventParams{.gridSpacing = 0.0}), std::invalid_argument);
  EXPECT_THROW(EventDetector(EventParams{.maxDihedral = 4.0}), std::invalid_argument);
  SheetFrame bad = frameOf(a);
  bad.heldVertices = {static_cast<int>(a.vertexCount())};
  EXPECT_THROW((void)one.detect(bad), std::invalid_argument);
  auto nan = a;
  nan.positions[3].x() = std::nan("");
  EXPECT_THROW((void)one.detect(frameOf(nan)), std::invalid_argument);
  EXPECT_THROW((void)one.detect(SheetFrame{}), std::invalid_argument);
}

}  // namespace
}  // namespace crumple::sound
