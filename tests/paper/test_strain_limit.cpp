// The strain limit of S_P (strain_limit.hpp): the Levenberg-Marquardt length
// projection, the rigid fit (Kabsch 1976), the transfer by pattern and the
// whole stage with its carried start and handle lag.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "crumple/paper/strain_limit.hpp"

namespace crumple::paper {
namespace {

using Tri = std::array<int, 3>;

// An n x m grid of squares (each split in two) over w x h metres.
struct Grid {
  std::vector<Vec2> pattern;
  std::vector<Tri> triangles;
  int n = 0, m = 0;
  [[nodiscard]] int at(int i, int j) const { return j * (n + 1) + i; }
};

Grid makeGrid(int n, int m, double w, double h) {
  Grid g;
  g.n = n;
  g.m = m;
  for (int j = 0; j <= m; ++j)
    for (int i = 0; i <= n; ++i) g.pattern.emplace_back(w * i / n, h * j / m);
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < n; ++i) {
      g.triangles.push_back({g.at(i, j), g.at(i + 1, j), g.at(i + 1, j + 1)});
      g.triangles.push_back({g.at(i, j), g.at(i + 1, j + 1), g.at(i, j + 1)});
    }
  return g;
}

std::vector<Vec3> lift(const std::vector<Vec2>& p) {
  std::vector<Vec3> x;
  for (const Vec2& q : p) x.emplace_back(q.x(), q.y(), 0.0);
  return x;
}

// Rolled onto a cylinder of radius r about the y axis: an isometry.
std::vector<Vec3> roll(const std::vector<Vec2>& p, double r) {
  std::vector<Vec3> x;
  for (const Vec2& q : p)
    x.emplace_back(r * std::sin(q.x() / r), q.y(), r - r * std::cos(q.x() / r));
  return x;
}

TEST(LengthProjector, MeasuresStrainAgainstThePattern) {
  const Grid g = makeGrid(4, 3, 0.1, 0.06);
  const LengthProjector p(g.pattern, g.triangles);
  EXPECT_EQ(p.edgeCount(), 4u * 4 + 3u * 5 + 4u * 3);
  std::vector<Vec3> x = lift(g.pattern);
  EXPECT_NEAR(p.strain(x).first, 0.0, 1e-15);
  for (Vec3& v : x) v.x() *= 1.05;
  // Horizontal edges stretch by 5 %, vertical ones not at all.
  EXPECT_NEAR(p.strain(x).first, 0.05, 1e-12);
}

TEST(LengthProjector, RestoresLengthsWithHeldVerticesUnmoved) {
  const Grid g = makeGrid(8, 5, 0.1, 0.06);
  const LengthProjector p(g.pattern, g.triangles);
  std::vector<Vec3> x = roll(g.pattern, 0.03);
  // Deterministic noise of up to 8 % of an edge (1.25 cm edges).
  for (std::size_t i = 0; i < x.size(); ++i)
    x[i] += 1e-3 * Vec3(std::sin(7.1 * i), std::cos(3.3 * i), std::sin(1.7 * i + 0.5));
  std::vector<char> held(x.size(), 0);
  held[static_cast<std::size_t>(g.at(0, 0))] = 1;
  held[static_cast<std::size_t>(g.at(g.n, g.m))] = 1;
  const std::vector<Vec3> start = x;
  const auto before = p.strain(x);
  ASSERT_GT(before.first, 0.05);
  const LengthProjectionStats s = p.project(x, held, 1e-4, 50);
  EXPECT_LE(s.maxAfter, 1e-4);
  EXPECT_LT(s.meanAfter, 0.01 * before.second);
  EXPECT_GT(s.iterations, 0);
  EXPECT_EQ(x[static_cast<std::size_t>(g.at(0, 0))], start[static_cast<std::size_t>(g.at(0, 0))]);
  EXPECT_EQ(x[static_cast<std::size_t>(g.at(g.n, g.m))],
            start[static_cast<std::size_t>(g.at(g.n, g.m))]);
}

// Contacts as constraints of the projection (KeepOut): a sheet rolled
// about an axis, with up to 1 mm of noise, whose vertices in every other
// column must stay on the axis side of the roll's tangent plane at their
// place (as if a layer lay under them there), gets its lengths back within
// 0.1 % and ends out of the planes; the same projection without them
// leaves vertices inside.
TEST(LengthProjector, KeepsTheContactsItIsGiven) {
  const Grid g = makeGrid(8, 5, 0.1, 0.06);
  const double radius = 0.03;
  std::vector<Vec3> x = roll(g.pattern, radius);
  std::vector<KeepOut> keepOut;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const Vec3 axis(0.0, x[i].y(), radius);        // the roll's axis is y at (0, ., r)
    if (static_cast<int>(i) % (g.n + 1) % 2 == 1)  // every other column
      keepOut.push_back({static_cast<int>(i), x[i], (axis - x[i]).normalized()});
  }
  std::vector<char> held(x.size(), 0);
  held[static_cast<std::size_t>(g.at(0, 0))] = 1;
  held[static_cast<std::size_t>(g.at(g.n, g.m))] = 1;
  for (std::size_t i = 0; i < x.size(); ++i)  // the held corners stay on the roll
    if (held[i] == 0)
      x[i] += 1e-3 * Vec3(std::sin(7.1 * i), std::cos(3.3 * i), std::sin(1.7 * i + 0.5));
  const auto deepest = [&](const std::vector<Vec3>& y) {
    double d = 0.0;
    for (const KeepOut& k : keepOut)
      d = std::max(d, -k.normal.dot(y[static_cast<std::size_t>(k.vertex)] - k.point));
    return d;
  };
  LengthProjector free(g.pattern, g.triangles);
  std::vector<Vec3> unconstrained = x;
  EXPECT_LE(free.project(unconstrained, held, 1e-3, 50).maxAfter, 1e-3);
  EXPECT_GT(deepest(unconstrained), 2e-4) << "without them the projection goes inside";
  LengthProjector kept(g.pattern, g.triangles);
  kept.setKeepOut(keepOut);
  std::vector<Vec3> constrained = x;
  EXPECT_LE(kept.project(constrained, held, 1e-3, 50).maxAfter, 1e-3);
  EXPECT_LT(deepest(constrained), 2e-5);
}

// Self-contact as a guard on the projection: a compressed triangle whose
// free corner, 1 mm over a layer of the sheet, gets its lengths back by
// moving down through that layer (its two edges pass through it) without
// the guard; with it the corner stays on its side and the edges do not.
TEST(LengthProjector, TheCrossingGuardKeepsTheSheetOutOfItself) {
  const std::vector<Tri> triangles{{0, 1, 2}, {3, 4, 5}};
  const std::vector<Vec2> pattern{{1.0, 0.0},    {1.1, 0.0},     {1.0, 0.1},
                                  {0.005, 0.01}, {0.0, 0.00141}, {0.01, 0.00141}};
  std::vector<Vec3> x{{-0.05, -0.05, 0.0}, {0.05, -0.05, 0.0},   {0.0, 0.05, 0.0},
                      {0.0, 0.0, 0.001},   {-0.005, 0.0, 0.003}, {0.005, 0.0, 0.003}};
  std::vector<char> held{1, 1, 1, 0, 1, 1};
  constexpr double kThickness = 1e-4;
  LengthProjector free(pattern, triangles);
  free.setCrossingGuard(kThickness);  // to count them
  ASSERT_EQ(free.crossings(x), 0u);
  free.setCrossingGuard(0.0);
  std::vector<Vec3> unguarded = x;
  free.project(unguarded, held, 1e-6, 50);
  free.setCrossingGuard(kThickness);
  EXPECT_EQ(free.crossings(unguarded), 2u) << "without the guard it passes through";
  EXPECT_LT(unguarded[3].z(), -0.005);
  LengthProjector guarded(pattern, triangles);
  guarded.setCrossingGuard(kThickness);
  std::vector<Vec3> kept = x;
  guarded.project(kept, held, 1e-6, 50);
  EXPECT_EQ(guarded.crossings(kept), 0u);
  EXPECT_GT(kept[3].z(), 0.0) << "the corner stays over the layer";
}

TEST(LengthProjector, NeverRaisesTheMaxStrain) {
  // Two held corners further apart than the sheet reaches: no isometry; the
  // projection lowers the residual and returns its iterate of least max.
  const Grid g = makeGrid(6, 3, 0.1, 0.05);
  const LengthProjector p(g.pattern, g.triangles);
  std::vector<Vec3> x = lift(g.pattern);
  for (Vec3& v : x) v.x() *= 1.1;
  std::vector<char> held(x.size(), 0);
  held[static_cast<std::size_t>(g.at(0, 0))] = 1;
  held[static_cast<std::size_t>(g.at(g.n, 0))] = 1;
  x[static_cast<std::size_t>(g.at(g.n, 0))].x() = 0.103;  // the held pair 3 % beyond reach
  // The objective, sum_e r_e^2 (the max may rise: it is not what is minimised).
  const auto cost = [&](const std::vector<Vec3>& y) {
    double c = 0.0;
    for (const Tri& t : g.triangles)
      for (int k = 0; k < 3; ++k) {
        const auto a = static_cast<std::size_t>(t[static_cast<std::size_t>(k)]);
        const auto b = static_cast<std::size_t>(t[static_cast<std::size_t>((k + 1) % 3)]);
        const double rest = (g.pattern[a] - g.pattern[b]).norm();
        const double r = ((y[a] - y[b]).norm() - rest) / rest;
        c += r * r;
      }
    return c;
  };
  const double before = cost(x);
  const double maxBefore = p.strain(x).first;
  const LengthProjectionStats s = p.project(x, held, 0.0, 40);
  EXPECT_LT(cost(x), before);
  EXPECT_LT(s.maxAfter, maxBefore);
  EXPECT_NEAR(s.maxAfter, p.strain(x).first, 1e-15);
  // The bottom row between the held pair stays strained by about 3 %.
  EXPECT_GT(s.maxAfter, 0.02);
  EXPECT_LT(s.maxAfter, 0.05);
}

TEST(RigidMotion, RecoversARigidMotion) {
  const Mat3 r = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Vec3 t(0.1, -0.2, 0.3);
  const std::vector<Vec3> a{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.3, 0.2, 0.9}};
  std::vector<Vec3> b;
  for (const Vec3& p : a) b.push_back(r * p + t);
  const RigidMotion m = fitRigidMotion(a, b);
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_LT((m.apply(a[i]) - b[i]).norm(), 1e-12);
  EXPECT_NEAR(m.rotation.determinant(), 1.0, 1e-12);
}

TEST(RigidMotion, TwoPointsAndOnePoint) {
  const std::vector<Vec3> a{{0, 0, 0}, {1, 0, 0}};
  const std::vector<Vec3> b{{1, 1, 1}, {1, 2, 1}};  // same distance, turned by 90 degrees
  const RigidMotion m = fitRigidMotion(a, b);
  EXPECT_LT((m.apply(a[0]) - b[0]).norm(), 1e-12);
  EXPECT_LT((m.apply(a[1]) - b[1]).norm(), 1e-12);
  EXPECT_NEAR(m.rotation.determinant(), 1.0, 1e-12);
  const RigidMotion one = fitRigidMotion({Vec3(1, 2, 3)}, {Vec3(2, 2, 2)});
  EXPECT_EQ(one.rotation, Mat3::Identity());
  EXPECT_LT((one.apply(Vec3(0, 0, 0)) - Vec3(1, 0, -1)).norm(), 1e-15);
}

TEST(TransferByPattern, InterpolatesInsideTheOldTriangles) {
  const Grid coarse = makeGrid(2, 2, 0.1, 0.1);
  const std::vector<Vec3> x = roll(coarse.pattern, 0.05);
  // The same points come back exactly; a midpoint is the mean of its ends.
  const std::vector<Vec3> same =
      transferByPattern(coarse.pattern, coarse.triangles, x, coarse.pattern);
  for (std::size_t i = 0; i < x.size(); ++i) EXPECT_LT((same[i] - x[i]).norm(), 1e-15);
  const std::vector<Vec2> mid{0.5 * (coarse.pattern[0] + coarse.pattern[1]), Vec2(-0.01, 0.0)};
  const std::vector<Vec3> m = transferByPattern(coarse.pattern, coarse.triangles, x, mid);
  EXPECT_LT((m[0] - 0.5 * (x[0] + x[1])).norm(), 1e-15);
  // Outside the pattern: clamped onto the nearest triangle (its corner here).
  EXPECT_LT((m[1] - x[0]).norm(), 1e-15);
}

// A step on one grid: its start `before` and its handles; limit() runs the
// stage on `x` with S_P unchanged over the step.
struct Shot {
  Grid g = makeGrid(6, 4, 0.1, 0.06);
  std::vector<int> handles;
  std::vector<Vec3> before;
  StrainLimitStats limit(std::vector<Vec3>& x, const std::vector<Vec3>& targets) const {
    return limitStrain(
        {g.pattern, g.triangles, g.pattern, g.triangles, before, true, handles, targets, {}}, x);
  }
};

TEST(LimitStrain, LeavesAGoodSheetAlone) {
  Shot s;
  s.handles = {s.g.at(0, 0)};
  s.before = lift(s.g.pattern);
  std::vector<Vec3> x = roll(s.g.pattern, 0.04);
  const std::vector<Vec3> targets{x[static_cast<std::size_t>(s.handles[0])]};
  const std::vector<Vec3> start = x;
  const StrainLimitStats st = s.limit(x, targets);
  EXPECT_FALSE(st.ran);
  EXPECT_EQ(x, start);
  EXPECT_EQ(st.lag, 0.0);
}

TEST(LimitStrain, ACarriedStartFollowsARigidHandleMotion) {
  // Three handles turned by 60 degrees and moved; the stepped sheet is a
  // crushed mess far from them. The carried start takes the sheet along.
  Shot s;
  s.handles = {s.g.at(0, 0), s.g.at(s.g.n, 0), s.g.at(0, s.g.m)};
  s.before = roll(s.g.pattern, 0.04);
  const Mat3 r = Eigen::AngleAxisd(std::numbers::pi / 3, Vec3(0, 0, 1)).toRotationMatrix();
  const Vec3 t(0.02, 0.01, -0.03);
  std::vector<Vec3> targets;
  for (int h : s.handles) targets.push_back(r * s.before[static_cast<std::size_t>(h)] + t);
  std::vector<Vec3> x(s.before.size(), Vec3::Zero());  // crushed to a point
  const StrainLimitStats st = s.limit(x, targets);
  EXPECT_TRUE(st.ran);
  EXPECT_TRUE(st.carried);
  EXPECT_LE(st.maxAfter, 0.01);
  EXPECT_LT(st.lag, 1e-12);
  for (std::size_t i = 0; i < x.size(); ++i) EXPECT_LT((x[i] - (r * s.before[i] + t)).norm(), 1e-4);
}

TEST(LimitStrain, HandlesBeyondTheSheetsReachLag) {
  // Two corners pulled 10 % further apart than the pattern allows: no
  // configuration meets 2 % with them on their targets, so they lag, and the
  // sheet stays within the bound.
  Shot s;
  s.handles = {s.g.at(0, 0), s.g.at(s.g.n, 0)};
  s.before = lift(s.g.pattern);
  const std::vector<Vec3> targets{Vec3(-0.005, 0, 0), Vec3(0.105, 0, 0)};
  std::vector<Vec3> x = s.before;
  for (Vec3& v : x) v.x() = -0.005 + 1.1 * v.x();
  const StrainLimitStats st = s.limit(x, targets);
  EXPECT_TRUE(st.ran);
  EXPECT_LE(st.maxAfter, 0.02);
  EXPECT_GT(st.lag, 0.001);  // they meet about 2 mm of the 10 mm asked
  EXPECT_LT(st.lag, 0.005);
  EXPECT_TRUE(st.lagVertex == s.handles[0] || st.lagVertex == s.handles[1]);
}

TEST(LimitStrain, AContactNoStartCanKeepGivesWayToTheBound) {
  // The step's start is 3 % over its pattern (as a rebuilt S_P can be), and
  // a contact asks the middle of the top edge 2 cm beyond where the sheet
  // reaches from its held corner: no start meets the bound and keeps the
  // contact. The bound wins, the contact is dropped for the step (the
  // failsafe pushes again at the next one).
  Shot s;
  s.handles = {s.g.at(0, 0)};
  s.before = lift(s.g.pattern);
  for (Vec3& v : s.before) v.x() *= 1.03;
  const std::vector<Vec3> targets{Vec3(0.001, 0, 0)};
  std::vector<Vec3> x = s.before;
  const int top = s.g.at(s.g.n / 2, s.g.m);
  const std::vector<KeepOut> keepOut{{top, Vec3(0.05, 0.08, 0.0), Vec3::UnitY()}};
  const auto limit = [&](std::vector<KeepOut> k) {
    return limitStrain({s.g.pattern,
                        s.g.triangles,
                        s.g.pattern,
                        s.g.triangles,
                        s.before,
                        true,
                        s.handles,
                        targets,
                        {},
                        0.02,
                        30,
                        std::move(k)},
                       x);
  };
  const StrainLimitStats st = limit(keepOut);
  EXPECT_TRUE(st.ran);
  EXPECT_TRUE(st.droppedKeepOut);
  EXPECT_LE(st.maxAfter, 0.02);
  EXPECT_LE(LengthProjector(s.g.pattern, s.g.triangles).strain(x).first, 0.02);
  x = s.before;
  EXPECT_FALSE(limit({}).droppedKeepOut);  // no contact, nothing to drop
}

TEST(LimitStrain, EachHandleLagsOnlyAsFarAsItMust) {
  // The two bottom corners pulled 10 % beyond their reach; of the top
  // corners one stays and one is lifted 5 mm, which the sheet can follow by
  // folding. The bottom corners lag; the top ones do not lag with them
  // (one uniform lag of every handle holds them back by their fraction).
  Shot s;
  s.handles = {s.g.at(0, 0), s.g.at(s.g.n, 0), s.g.at(0, s.g.m), s.g.at(s.g.n, s.g.m)};
  s.before = lift(s.g.pattern);
  const Vec3 left = s.before[static_cast<std::size_t>(s.handles[2])];
  const Vec3 right = s.before[static_cast<std::size_t>(s.handles[3])];
  const std::vector<Vec3> targets{Vec3(-0.005, 0, 0), Vec3(0.105, 0, 0), left,
                                  right + Vec3(0, 0, 0.005)};
  std::vector<Vec3> x = s.before;
  for (Vec3& v : x) v.x() = -0.005 + 1.1 * v.x();
  const StrainLimitStats st = s.limit(x, targets);
  EXPECT_TRUE(st.ran);
  EXPECT_LE(st.maxAfter, 0.02);
  ASSERT_EQ(st.handleLags.size(), 4U);
  for (std::size_t h = 0; h < 4; ++h) EXPECT_EQ(st.handleLags[h].first, s.handles[h]);
  EXPECT_GT(st.handleLags[0].second + st.handleLags[1].second, 0.002);
  // Measured: 0.003 mm (top left) and 0.23 mm (top right), both 1.15 mm with
  // one uniform lag.
  EXPECT_LT(st.handleLags[2].second, 0.1 * 0.005);
  EXPECT_LT(st.handleLags[3].second, 0.1 * 0.005);
  EXPECT_NEAR(st.lag, std::max(st.handleLags[0].second, st.handleLags[1].second), 1e-15);
}

TEST(LengthProjector, TowardsTargetsWithinTheBound) {
  // projectTowards from the flat sheet: a corner asked 5 mm up reaches it
  // (the sheet bends), one asked 10 mm along the sheet, beyond its reach,
  // stops where the bound holds, and no edge ends over the bound.
  const Grid g = makeGrid(6, 4, 0.1, 0.06);
  const LengthProjector p(g.pattern, g.triangles);
  std::vector<Vec3> x = lift(g.pattern);
  std::vector<char> held(x.size(), 0);
  held[static_cast<std::size_t>(g.at(0, 0))] = 1;
  held[static_cast<std::size_t>(g.at(0, g.m))] = 1;
  const int up = g.at(g.n, g.m), along = g.at(g.n, 0);
  const std::vector<Vec3> targets{x[static_cast<std::size_t>(up)] + Vec3(0, 0, 0.005),
                                  x[static_cast<std::size_t>(along)] + Vec3(0.01, 0, 0)};
  p.projectTowards(x, held, {up, along}, targets, 0.02, 200);
  EXPECT_LE(p.strain(x).first, 0.02);
  EXPECT_LT((x[static_cast<std::size_t>(up)] - targets[0]).norm(), 2e-4);
  const double reach = (x[static_cast<std::size_t>(along)] - targets[1]).norm();
  EXPECT_GT(reach, 0.007);  // at most ~2 % of 10 cm of the 10 mm
  EXPECT_LT(reach, 0.0099);
}

// The lag search's start as the strain limit hands it over when handles
// lag: their own edges stretched to the soft bound, the rest of the sheet
// as it was. Here a strip held along its left end, bowed into an arc, with
// its two right corners asked 2 cm closer to the left end: it can bend
// further (an isometry) to bring them there. A Gauss-Newton model without
// the bound's penalty below the soft bound proposes moving the handles
// alone, every trial breaks through the bound and is rejected, and the
// search stops where it started (samples/crumple's handles stood 31 mm
// behind a sheet that no longer moved).
TEST(LengthProjector, TowardsBendsTheSheetBehindHandlesAtTheBound) {
  const Grid g = makeGrid(8, 2, 0.1, 0.04);
  const LengthProjector p(g.pattern, g.triangles);
  std::vector<Vec3> x = roll(g.pattern, 0.08);
  std::vector<char> held(x.size(), 0);
  for (int j = 0; j <= g.m; ++j) held[static_cast<std::size_t>(g.at(0, j))] = 1;
  const std::vector<int> handles{g.at(g.n, 0), g.at(g.n, g.m)};
  const double soft = LengthProjector::kSoftBound * 0.02;
  std::vector<Vec3> targets;
  for (int h : handles) {
    // The edge to its left neighbour at the soft bound.
    Vec3& xh = x[static_cast<std::size_t>(h)];
    const Vec3& left = x[static_cast<std::size_t>(h - 1)];
    xh = left + (xh - left).normalized() * (1.0 + soft) * 0.1 / g.n;
    targets.push_back(xh + Vec3(-0.02, 0.0, 0.0));
  }
  ASSERT_NEAR(p.strain(x).first, soft, 1e-9);
  const double before = (x[static_cast<std::size_t>(handles[0])] - targets[0]).norm();
  p.projectTowards(x, held, handles, targets, 0.02, 60);
  EXPECT_LE(p.strain(x).first, 0.02);
  for (std::size_t h = 0; h < handles.size(); ++h)
    EXPECT_LT((x[static_cast<std::size_t>(handles[h])] - targets[h]).norm(), 0.1 * before) << h;
}

TEST(LimitStrain, MergesAFramesHandleLagsByTheirLargest) {
  std::vector<std::pair<int, double>> frame{{3, 0.002}, {7, 0.0}};
  mergeHandleLags({{7, 0.001}, {3, 0.001}, {9, 0.004}}, frame);
  const std::vector<std::pair<int, double>> expected{{3, 0.002}, {7, 0.001}, {9, 0.004}};
  EXPECT_EQ(frame, expected);
}

TEST(LimitStrain, ARebuiltSheetIsCarriedByPattern) {
  // The step's start is a coarser mesh of the same pattern: the carried start
  // interpolates it.
  Shot s;
  const Grid coarse = makeGrid(3, 2, 0.1, 0.06);
  s.handles = {0};
  const std::vector<Vec3> before = lift(coarse.pattern);
  const std::vector<Vec3> targets{Vec3(0.0, 0.0, 0.01)};
  std::vector<Vec3> x(s.g.pattern.size(), Vec3::Zero());  // crushed to a point
  const StrainLimitStats st = limitStrain({s.g.pattern,
                                           s.g.triangles,
                                           coarse.pattern,
                                           coarse.triangles,
                                           before,
                                           false,
                                           s.handles,
                                           targets,
                                           {}},
                                          x);
  EXPECT_TRUE(st.carried);
  EXPECT_LE(st.maxAfter, 0.01);
  EXPECT_LT(st.lag, 1e-12);
  EXPECT_NEAR(x.back().z(), 0.01, 1e-9);
}

}  // namespace
}  // namespace crumple::paper
