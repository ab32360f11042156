// The tearing primitives (thesis 3.2.2 and 3.3): the fibers'
// texture, the Griffith criterion and the tip's propagation, the clustering
// of the tip's forces into two pulls, and the detail path.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <numbers>

#include "crumple/sim/elastic_sheet.hpp"
#include "crumple/tear/candidates.hpp"
#include "crumple/tear/cut.hpp"
#include "crumple/tear/detail_path.hpp"
#include "crumple/tear/fiber_texture.hpp"
#include "crumple/tear/griffith.hpp"
#include "crumple/tear/lip_masks.hpp"
#include "crumple/tear/tear_step.hpp"
#include "crumple/tear/tearing.hpp"
#include "crumple/tear/tip_pulls.hpp"

namespace crumple::tear {
namespace {

// Mean absolute difference between neighbouring texels along u and along v.
std::array<double, 2> roughness(const FiberTexture& t) {
  double du = 0.0, dv = 0.0;
  long n = 0;
  for (int j = 0; j + 1 < t.height(); ++j)
    for (int i = 0; i + 1 < t.width(); ++i, ++n) {
      du += std::abs(t.texel(i + 1, j) - t.texel(i, j));
      dv += std::abs(t.texel(i, j + 1) - t.texel(i, j));
    }
  return {du / static_cast<double>(n), dv / static_cast<double>(n)};
}

TEST(FiberTexture, SpansZeroToOneAndIsAPureFunctionOfTheSeed) {
  const FiberTexture a(Vec2::Zero(), Vec2(0.05, 0.03), FiberTextureParams{});
  EXPECT_EQ(a.width(), 200);
  EXPECT_EQ(a.height(), 120);
  double lo = 1.0, hi = 0.0;
  for (int j = 0; j < a.height(); ++j)
    for (int i = 0; i < a.width(); ++i) {
      lo = std::min(lo, a.texel(i, j));
      hi = std::max(hi, a.texel(i, j));
    }
  EXPECT_EQ(lo, 0.0);
  EXPECT_EQ(hi, 1.0);
  const FiberTexture same(Vec2::Zero(), Vec2(0.05, 0.03), FiberTextureParams{});
  FiberTextureParams other;
  other.seed = 2;
  const FiberTexture different(Vec2::Zero(), Vec2(0.05, 0.03), other);
  int equal = 0, changed = 0;
  for (int j = 0; j < a.height(); ++j)
    for (int i = 0; i < a.width(); ++i) {
      equal += a.texel(i, j) == same.texel(i, j) ? 1 : 0;
      changed += std::abs(a.texel(i, j) - different.texel(i, j)) > 1e-3 ? 1 : 0;
    }
  EXPECT_EQ(equal, a.width() * a.height());
  EXPECT_GT(changed, a.width() * a.height() / 2);
  // Bilinear sampling meets the texels at their centres.
  EXPECT_DOUBLE_EQ(a.sample(a.centre(17, 33)), a.texel(17, 33));
}

TEST(FiberTexture, AnisotropicFibersAreLongerAlongTheirDirection) {
  const auto iso = roughness(FiberTexture(Vec2::Zero(), Vec2(0.04, 0.04), FiberTextureParams{}));
  FiberTextureParams p;
  p.anisotropy = 4.0;
  p.fiberDirection = Vec2::UnitX();
  const auto aniso = roughness(FiberTexture(Vec2::Zero(), Vec2(0.04, 0.04), p));
  std::cout << "[ measure ] texel-to-texel change along / across: isotropic " << iso[0] / iso[1]
            << ", anisotropy 4 " << aniso[0] / aniso[1] << "\n";
  EXPECT_NEAR(iso[0] / iso[1], 1.0, 0.2);
  EXPECT_LT(aniso[0] / aniso[1], 0.5) << "smoother along the fibers";
}

TEST(FiberTexture, RejectsBadParameters) {
  FiberTextureParams p;
  p.texelSize = 0.0;
  EXPECT_THROW(FiberTexture(Vec2::Zero(), Vec2(0.01, 0.01), p), std::invalid_argument);
  p = {};
  p.anisotropy = 0.5;
  EXPECT_THROW(FiberTexture(Vec2::Zero(), Vec2(0.01, 0.01), p), std::invalid_argument);
  p = {};
  p.texelSize = 1e-7;
  EXPECT_THROW(FiberTexture(Vec2::Zero(), Vec2(1.0, 1.0), p), std::invalid_argument)
      << "10^14 texels";
  EXPECT_THROW(FiberTexture(Vec2::Zero(), Vec2(0.0, 0.01), FiberTextureParams{}),
               std::invalid_argument);
}

TEST(Griffith, FractureEnergyIsResistanceTimesFibersTimesDamage) {
  EXPECT_DOUBLE_EQ(fractureEnergy(0.005, 0.6, 1.0), 0.003);
  EXPECT_DOUBLE_EQ(fractureEnergy(0.005, 0.6, 0.5), 0.0015) << "a tip is weaker";
  EXPECT_THROW(fractureEnergy(0.005, 1.5, 1.0), std::invalid_argument);
  EXPECT_THROW(fractureEnergy(-1.0, 0.5, 1.0), std::invalid_argument);
}

TEST(Griffith, TwoPullsOpenTheTearAlongTheirBisectorAwayFromThem) {
  // The tip at the origin, pulled toward A = (-1, -1) and B = (1, -1).
  const Propagation p = propagation(Vec2(-1, -1).normalized(), Vec2(1, -1).normalized());
  EXPECT_NEAR(p.angle, 0.5 * std::numbers::pi, 1e-12);
  EXPECT_NEAR(p.energyRelease, 2.0 * std::cos(0.25 * std::numbers::pi), 1e-12);
  EXPECT_TRUE(p.direction.isApprox(Vec2(0, 1), 1e-12)) << "away from the pulling points";
  // Parallel pulls (flaps pulled back together) release the most: |L| + |R|.
  EXPECT_NEAR(propagation(Vec2(0, -2), Vec2(0, -1)).energyRelease, 3.0, 1e-12);
  // Straight apart: the sheet is stretched across the tear, nothing released.
  EXPECT_NEAR(propagation(Vec2(-1, 0), Vec2(1, 0)).energyRelease, 0.0, 1e-12);
  // The Griffith criterion: the tip moves by V E_r only when E_r >= E_f.
  const Vec2 tip(0.3, 0.2);
  EXPECT_EQ(advanceTip(tip, p, p.energyRelease + 1e-9, 0.01), tip);
  EXPECT_TRUE(advanceTip(tip, p, p.energyRelease, 0.01)
                  .isApprox(tip + 0.01 * p.energyRelease * Vec2(0, 1), 1e-15));
}

TEST(Griffith, ATearPulledFromTwoFixedPointsFollowsAHyperbola) {
  // Roman 2013 (thesis 3.3.1, Fig. 3.13): with the pulls toward two points
  // A and B fixed in the pattern, the tip moves along the bisector of AS and
  // BS, so |SA| - |SB| stays constant: a hyperbola with foci A and B.
  const Vec2 a(-0.05, -0.04), b(0.06, -0.03);
  Vec2 s(0.01, 0.0);
  const double invariant = (s - a).norm() - (s - b).norm();
  double travelled = 0.0, worst = 0.0;
  for (int step = 0; step < 200; ++step) {
    const Propagation p = propagation((a - s).normalized(), (b - s).normalized());
    const Vec2 next = advanceTip(s, p, 0.0, 2.5e-4 / p.energyRelease);  // 0.25 mm steps
    travelled += (next - s).norm();
    s = next;
    worst = std::max(worst, std::abs((s - a).norm() - (s - b).norm() - invariant));
  }
  std::cout << "[ measure ] after " << travelled << " m of tear, |SA| - |SB| drifted by " << worst
            << " m\n";
  EXPECT_NEAR(travelled, 0.05, 1e-9);
  EXPECT_LT(worst, 1e-3 * travelled) << "first-order steps stay on the hyperbola";
  EXPECT_GT(s.y(), 0.04) << "it ran away from the pulling points";
}

TEST(Griffith, ForcesAtATipSplitIntoTheirTwoPulls) {
  // Three forces toward the upper left and two toward the upper right, in
  // the XY plane; the first guess of the tear direction is off by 40 deg.
  const std::vector<Vec3> forces{Vec3(-1.0, 0.9, 0), Vec3(-1.2, 1.1, 0), Vec3(-0.8, 1.0, 0),
                                 Vec3(1.0, 1.2, 0), Vec3(0.9, 0.8, 0)};
  const double guess = 40.0 * std::numbers::pi / 180.0;
  const ForceClusters c =
      clusterTipForces(forces, Vec3::UnitZ(), Vec3(std::sin(guess), -std::cos(guess), 0));
  EXPECT_TRUE(c.converged);
  EXPECT_LE(c.iterations, 10);
  const Vec3 upperLeft = forces[0] + forces[1] + forces[2], upperRight = forces[3] + forces[4];
  const bool asIs = c.left.isApprox(upperLeft, 1e-12) && c.right.isApprox(upperRight, 1e-12);
  const bool swapped = c.left.isApprox(upperRight, 1e-12) && c.right.isApprox(upperLeft, 1e-12);
  EXPECT_TRUE(asIs || swapped) << c.left.transpose() << " | " << c.right.transpose();
}

TEST(DetailPath, RunsFromTipToTipRougherThanTheStraightSegment) {
  // At the default resolution (0.25 mm texels, 2 mm features, p = 0.5): the
  // tear paths must be at least 1.15 times the straight length
  // between tips. 2 cm segments in 8 directions, fiber seeds 1-4.
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    FiberTextureParams fp;
    fp.seed = seed;
    const FiberTexture fibers(Vec2::Zero(), Vec2(0.06, 0.06), fp);
    double ratio = 0.0;
    for (int k = 0; k < 8; ++k) {
      const double angle = k * std::numbers::pi / 8.0;
      const Vec2 from = Vec2(0.03, 0.03) - 0.01 * Vec2(std::cos(angle), std::sin(angle));
      const Vec2 to = Vec2(0.03, 0.03) + 0.01 * Vec2(std::cos(angle), std::sin(angle));
      const auto path = detailPath(fibers, from, to, DetailPathParams{});
      ASSERT_GE(path.size(), 2u);
      EXPECT_EQ(path.front(), from);
      EXPECT_EQ(path.back(), to);
      // Every step forward, within pi/2 of the direction to the end.
      for (std::size_t i = 1; i + 1 < path.size(); ++i)
        EXPECT_GT((path[i] - path[i - 1]).dot(to - path[i - 1]), -1e-12) << "segment " << k;
      EXPECT_EQ(path, detailPath(fibers, from, to, DetailPathParams{})) << "deterministic";
      ratio += pathLength(path) / (to - from).norm() / 8.0;
    }
    std::cout << "[ measure ] seed " << seed
              << ": detail path / straight segment, mean over 8 directions " << ratio << "\n";
    EXPECT_GE(ratio, 1.15) << "seed " << seed;
  }
  const FiberTexture fibers(Vec2::Zero(), Vec2(0.06, 0.06), FiberTextureParams{});
  // All stress and no fibers: the walk hugs the segment.
  DetailPathParams straight;
  straight.blend = 1.0;
  const auto path = detailPath(fibers, Vec2(0.02, 0.03), Vec2(0.04, 0.03), straight);
  EXPECT_NEAR(pathLength(path), 0.02, 0.5e-3) << "two texels";
}

// A 4 x 4 cm sheet of 1 cm cells, without the triangles whose centroid
// lies in `cut` (a notch or a hole).
template <typename Cut>
mesh::SheetMesh sheetWithout(Cut cut) {
  mesh::SheetMesh m = mesh::makeRectangleSheet(0.04, 0.04, 0.01);
  std::vector<std::array<int, 3>> kept;
  for (const auto& t : m.triangles) {
    const Vec2 c =
        (m.pattern[static_cast<std::size_t>(t[0])] + m.pattern[static_cast<std::size_t>(t[1])] +
         m.pattern[static_cast<std::size_t>(t[2])]) /
        3.0;
    if (!cut(c)) kept.push_back(t);
  }
  m.triangles = kept;
  m.regionOfTriangle.assign(kept.size(), 0);
  return m;
}

double loopArea(const mesh::SheetMesh& m, const std::vector<int>& loop) {
  double area = 0.0;
  for (std::size_t i = 0; i < loop.size(); ++i) {
    const Vec2& a = m.pattern[static_cast<std::size_t>(loop[i])];
    const Vec2& b = m.pattern[static_cast<std::size_t>(loop[(i + 1) % loop.size()])];
    area += 0.5 * (a.x() * b.y() - a.y() * b.x());
  }
  return area;
}

TEST(TearCandidates, BoundaryLoopsRunWithTheSheetOnTheirLeft) {
  const mesh::SheetMesh square = mesh::makeRectangleSheet(0.04, 0.04, 0.01);
  const auto loops = boundaryLoops(square);
  ASSERT_EQ(loops.size(), 1u);
  EXPECT_EQ(loops[0].size(), 16u) << "4 sides of 4 cells";
  EXPECT_NEAR(loopArea(square, loops[0]), 0.0016, 1e-15) << "counter-clockwise around the sheet";
  EXPECT_TRUE(inwardCorners(square, 0.1).empty()) << "a rectangle has no inward corner";
  // A 2 x 2 cm hole in the middle: a second loop, clockwise, four inward corners.
  const mesh::SheetMesh holed = sheetWithout(
      [](const Vec2& c) { return c.x() > 0.01 && c.x() < 0.03 && c.y() > 0.01 && c.y() < 0.03; });
  const auto holeLoops = boundaryLoops(holed);
  ASSERT_EQ(holeLoops.size(), 2u);
  EXPECT_NEAR(loopArea(holed, holeLoops[0]) + loopArea(holed, holeLoops[1]), 0.0016 - 0.0004,
              1e-15);
  EXPECT_EQ(inwardCorners(holed, 0.1).size(), 4u);
}

TEST(TearCandidates, ANotchsRootAndTheBordersOfHeldAreasAreCandidates) {
  // An L: the upper right quadrant cut away; its inner corner (2, 2) cm is
  // the only inward corner.
  const mesh::SheetMesh l =
      sheetWithout([](const Vec2& c) { return c.x() > 0.02 && c.y() > 0.02; });
  const int root = mesh::nearestPatternVertex(l, Vec2(0.02, 0.02));
  EXPECT_EQ(inwardCorners(l, 0.1), std::vector<int>{root});
  // A handle holds the corner (0, 0) and its two boundary neighbours; a
  // junction and a tip are given.
  std::vector<char> held(l.vertexCount(), 0);
  for (const Vec2& p : {Vec2(0, 0), Vec2(0.01, 0), Vec2(0, 0.01)})
    held[static_cast<std::size_t>(mesh::nearestPatternVertex(l, p))] = 1;
  const int tip = mesh::nearestPatternVertex(l, Vec2(0.04, 0.01));
  const int junction = mesh::nearestPatternVertex(l, Vec2(0.01, 0.04));
  const auto candidates = tearCandidates(l, {tip}, {junction, tip}, held, 0.1);
  std::vector<TearCandidate> expected{
      {tip, CandidateKind::Tip},
      {junction, CandidateKind::Junction},
      {mesh::nearestPatternVertex(l, Vec2(0.02, 0)), CandidateKind::HandleBorder},
      {mesh::nearestPatternVertex(l, Vec2(0, 0.02)), CandidateKind::HandleBorder},
      {root, CandidateKind::InwardCorner}};
  std::sort(expected.begin(), expected.end(),
            [](const TearCandidate& a, const TearCandidate& b) { return a.vertex < b.vertex; });
  EXPECT_EQ(candidates, expected);
}

TEST(LipMasks, EveryPixelIsOnTheSideOfTheDetailPathItLooksToBeOn) {
  // A straight path: the left side is where the cross product is positive.
  PixelGrid grid;
  grid.width = 48;
  grid.height = 40;
  const std::vector<Vec2> line{Vec2(0.0011, 0.0013), Vec2(0.0093, 0.0071)};
  const auto straight = leftOfPath(line, grid);
  const Vec2 d = line[1] - line[0];
  for (int j = 0; j < grid.height; ++j)
    for (int i = 0; i < grid.width; ++i) {
      const Vec2 r = grid.centre(i, j) - line[0];
      EXPECT_EQ(straight[static_cast<std::size_t>(j * grid.width + i)],
                d.x() * r.y() - d.y() * r.x() > 0.0 ? 1 : 0)
          << i << ", " << j;
    }
  // A detail path through the fibers, on a grid twice as fine as its
  // texels: every pixel clearly nearest to the inside of one segment (more
  // than half a pixel from the path) is on that segment's side.
  const FiberTexture fibers(Vec2::Zero(), Vec2(0.03, 0.03), FiberTextureParams{});
  const auto path = detailPath(fibers, Vec2(0.005, 0.012), Vec2(0.025, 0.018), DetailPathParams{});
  ASSERT_GT(pathLength(path), 1.15 * 0.0209);
  PixelGrid fine;
  fine.pixelSize = 1.25e-4;
  fine.width = fine.height = 240;
  const auto mask = leftOfPath(path, fine);
  long checked = 0, left = 0;
  for (int j = 0; j < fine.height; ++j)
    for (int i = 0; i < fine.width; ++i) {
      const Vec2 q = fine.centre(i, j);
      double best = 1.0;
      int side = -1;
      for (std::size_t k = 0; k + 1 < path.size(); ++k) {
        const Vec2 a = path[k], b = path[k + 1], ab = b - a;
        const double t = (q - a).dot(ab) / ab.squaredNorm();
        const double dist = (q - (a + std::clamp(t, 0.0, 1.0) * ab)).norm();
        if (dist < best) {
          best = dist;
          const bool interior = t > 0.05 && t < 0.95;
          side = interior ? (ab.x() * (q - a).y() - ab.y() * (q - a).x() > 0.0 ? 1 : 0) : -1;
        }
      }
      if (side < 0 || best < 0.5 * fine.pixelSize || best > 4.0 * fine.pixelSize) continue;
      ++checked;
      left += side;
      EXPECT_EQ(mask[static_cast<std::size_t>(j * fine.width + i)], side) << i << ", " << j;
    }
  std::cout << "[ measure ] " << checked << " pixels along the path checked, " << left
            << " of them left of it\n";
  EXPECT_GT(checked, 200);
  EXPECT_GT(left, checked / 4);
  EXPECT_LT(left, 3 * checked / 4);
}

// A 4 x 4 cm sheet (2.5 mm cells) slit from the bottom edge up to its
// middle along x = 2 cm: the slit's lips are separate vertices, its tip
// (2, 1) cm is shared. `peel` turns the flaps below y = 1 cm up (left) and
// down (right) about that line by this angle; `stretch` lengthens them
// along their length; `spread` moves them apart along X instead.
struct Slit {
  mesh::SheetMesh mesh;
  int tip = -1;
};
Slit slitSheet(double peel, double stretch, double spread) {
  Slit s;
  s.mesh = mesh::makeRectangleSheet(0.04, 0.04, 0.0025);
  mesh::placePattern(s.mesh, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY());
  mesh::SheetMesh& m = s.mesh;
  std::map<int, int> twin;  // slit vertex -> its copy on the left lip
  for (auto& t : m.triangles) {
    const Vec2 c =
        (m.pattern[static_cast<std::size_t>(t[0])] + m.pattern[static_cast<std::size_t>(t[1])] +
         m.pattern[static_cast<std::size_t>(t[2])]) /
        3.0;
    if (!(c.x() < 0.02 && c.y() < 0.01)) continue;
    for (int& v : t) {
      const Vec2 p = m.pattern[static_cast<std::size_t>(v)];
      if (std::abs(p.x() - 0.02) > 1e-12 || !(p.y() < 0.01 - 1e-12)) continue;
      auto [it, added] = twin.emplace(v, static_cast<int>(m.pattern.size()));
      if (added) {
        m.pattern.push_back(p);
        m.positions.push_back(m.positions[static_cast<std::size_t>(v)]);
      }
      v = it->second;
    }
  }
  s.tip = mesh::nearestPatternVertex(m, Vec2(0.02, 0.01));
  // Left lip: the copies and every vertex left of the slit.
  std::vector<char> left(m.vertexCount(), 0);
  for (const auto& t : m.triangles) {
    const Vec2 c =
        (m.pattern[static_cast<std::size_t>(t[0])] + m.pattern[static_cast<std::size_t>(t[1])] +
         m.pattern[static_cast<std::size_t>(t[2])]) /
        3.0;
    if (c.x() < 0.02)
      for (int v : t) left[static_cast<std::size_t>(v)] = 1;
  }
  for (std::size_t v = 0; v < m.vertexCount(); ++v) {
    const Vec2 p = m.pattern[v];
    if (!(p.y() < 0.01 - 1e-12)) continue;
    const double below = stretch * (0.01 - p.y());
    const bool isLeft = left[v] != 0 && !(p.x() > 0.02 + 1e-12);
    const double a = isLeft ? peel : -peel;
    const double dx = isLeft ? -spread : spread;
    m.positions[v] =
        Vec3(p.x() + dx * below / 0.01, 0.01 - below * std::cos(a), below * std::sin(a));
  }
  return s;
}

TipPulls pullsAtTip(const Slit& s) {
  sim::ElasticSheet sheet(s.mesh, sim::Material{}, sim::SimParams{});
  std::vector<TriangleForce> forces;
  for (const auto& f : sheet.membraneForcesOn(s.tip)) forces.push_back({f.triangle, f.force});
  return tipPulls(s.mesh, s.tip, forces, boundaryBisector(s.mesh, s.tip));
}

TEST(TipPulls, PeeledFlapsTearTheSlitOnwardAndReleaseMoreThanFannedOnes) {
  // The slit's tip: the boundary's bisector points up the slit, into the sheet.
  const Slit flat = slitSheet(0.0, 1.0, 0.0);
  EXPECT_TRUE(boundaryBisector(flat.mesh, flat.tip).isApprox(Vec2(0, 1), 1e-12));
  // Flaps peeled apart (up and down by 60 deg) and pulled taut (1 %): both
  // pulls point back down the flaps, the tear runs on up the slit and
  // releases nearly all of them (Roman's tearing, theta near 0).
  const TipPulls peeled = pullsAtTip(slitSheet(std::numbers::pi / 3.0, 1.01, 0.0));
  const Propagation p = propagation(peeled.left, peeled.right);
  std::cout << "[ measure ] peeled: pulls " << peeled.left.transpose() << " | "
            << peeled.right.transpose() << " N, theta " << p.angle << " rad, E_r "
            << p.energyRelease << " N, direction " << p.direction.transpose() << "\n";
  EXPECT_TRUE(peeled.clusters.converged);
  EXPECT_GT(peeled.left.norm(), 0.0);
  EXPECT_GT(peeled.right.norm(), 0.0);
  EXPECT_LT(p.angle, 0.5);
  EXPECT_GT(p.direction.dot(Vec2(0, 1)), 0.95) << "up the slit, into the sheet";
  EXPECT_GT(p.energyRelease, 0.8 * (peeled.left.norm() + peeled.right.norm()));
  // The same flaps fanned apart in the plane (their bottom corners moved
  // 1 mm outward): the pulls point to the flaps' far corners, wide apart,
  // and release a smaller part of themselves (cos(theta / 2)).
  const TipPulls apart = pullsAtTip(slitSheet(0.0, 1.0, 0.001));
  const Propagation q = propagation(apart.left, apart.right);
  const double fraction = q.energyRelease / (apart.left.norm() + apart.right.norm());
  std::cout << "[ measure ] fanned in the plane: theta " << q.angle << " rad, E_r "
            << q.energyRelease << " N, " << fraction << " of the pulls\n";
  EXPECT_GT(q.angle, 1.0);
  EXPECT_LT(fraction, 0.8);
  EXPECT_GT(q.direction.dot(Vec2(0, 1)), 0.95) << "still up the slit, by symmetry";
}

TEST(TearStep, TheSlitsTipTearsWhenTheReleaseBeatsTheFractureEnergy) {
  const auto run = [](const Slit& s, const TearParams& params) {
    sim::ElasticSheet sheet(s.mesh, sim::Material{}, sim::SimParams{});
    const FiberTexture fibers(Vec2::Zero(), Vec2(0.04, 0.04), FiberTextureParams{});
    const VertexForces forces = [&sheet](int v) {
      std::vector<TriangleForce> out;
      for (const auto& f : sheet.membraneForcesOn(v)) out.push_back({f.triangle, f.force});
      return out;
    };
    return testCandidates(s.mesh, fibers, {s.tip}, {}, std::vector<char>(s.mesh.vertexCount(), 0),
                          forces, params);
  };
  const Slit peeled = slitSheet(std::numbers::pi / 3.0, 1.01, 0.0);
  const auto tests = run(peeled, TearParams{});
  ASSERT_EQ(tests.size(), 1u) << "the slit's tip is the only candidate (the corners are convex)";
  const CandidateTest& t = tests[0];
  EXPECT_EQ(t.candidate, (TearCandidate{peeled.tip, CandidateKind::Tip}));
  EXPECT_TRUE(t.tears);
  const Vec2 from = peeled.mesh.pattern[static_cast<std::size_t>(peeled.tip)];
  EXPECT_TRUE(t.next.isApprox(
      from + TearParams{}.speed * t.propagation.energyRelease * t.propagation.direction, 1e-12));
  EXPECT_GT(t.next.y(), from.y());
  // A tougher paper (E_f beyond the release) holds; so does an unstrained sheet.
  TearParams tough;
  tough.resistance = 1e3;
  EXPECT_FALSE(run(peeled, tough)[0].tears);
  EXPECT_EQ(run(peeled, tough)[0].next, from);
  const Slit relaxed = slitSheet(0.0, 1.0, 0.0);
  EXPECT_FALSE(run(relaxed, TearParams{})[0].tears);
}

// Whether the open segment (a, b) passes through the inside of triangle t.
bool crossesInside(const mesh::SheetMesh& m, const std::array<int, 3>& t, const Vec2& a,
                   const Vec2& b) {
  // Sample the segment densely: any sample strictly inside the triangle.
  const Vec2 p0 = m.pattern[static_cast<std::size_t>(t[0])];
  const Vec2 p1 = m.pattern[static_cast<std::size_t>(t[1])];
  const Vec2 p2 = m.pattern[static_cast<std::size_t>(t[2])];
  const auto cross = [](const Vec2& u, const Vec2& v) { return u.x() * v.y() - u.y() * v.x(); };
  const double area = cross(p1 - p0, p2 - p0);
  for (int k = 1; k < 2000; ++k) {
    const Vec2 q = a + (b - a) * (k / 2000.0);
    const double w1 = cross(q - p0, p2 - p0) / area, w2 = cross(p1 - p0, q - p0) / area;
    const double w0 = 1.0 - w1 - w2;
    if (w0 > 1e-6 && w1 > 1e-6 && w2 > 1e-6) return true;
  }
  return false;
}

TEST(Cut, ATearsAdvanceBecomesTwoLipsThatNoTriangleCrosses) {
  for (const Vec2& to : {Vec2(0.0213, 0.0137), Vec2(0.031, 0.017), Vec2(0.02, 0.015)}) {
    mesh::SheetMesh m = mesh::makeRectangleSheet(0.04, 0.04, 0.005);
    mesh::placePattern(m, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY());
    const int from = mesh::nearestPatternVertex(m, Vec2(0.02, 0.0));
    const Vec2 start = m.pattern[static_cast<std::size_t>(from)];
    const std::size_t before = m.vertexCount();
    const CutResult cut = cutAlong(m, from, to);
    EXPECT_EQ(mesh::validate(m), "") << to.transpose();
    // The tip is the new point; every other chain vertex has a twin.
    EXPECT_TRUE(m.pattern[static_cast<std::size_t>(cut.tip)].isApprox(to, 1e-12));
    EXPECT_EQ(cut.twins.size(), cut.chain.size() - 1);
    EXPECT_GT(m.vertexCount(), before);
    for (std::size_t i = 0; i < cut.twins.size(); ++i)
      EXPECT_EQ(m.pattern[static_cast<std::size_t>(cut.twins[i])],
                m.pattern[static_cast<std::size_t>(cut.chain[i])]);
    // The sheet keeps its area, no triangle crosses the cut, and the
    // outline now runs up one lip and down the other.
    double area = 0.0;
    for (const auto& t : m.triangles) {
      const Vec2 a = m.pattern[static_cast<std::size_t>(t[0])];
      const Vec2 b = m.pattern[static_cast<std::size_t>(t[1])];
      const Vec2 c = m.pattern[static_cast<std::size_t>(t[2])];
      area += 0.5 * ((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
      EXPECT_FALSE(crossesInside(m, t, start, to));
    }
    EXPECT_NEAR(area, 0.0016, 1e-15);
    const auto loops = boundaryLoops(m);
    ASSERT_EQ(loops.size(), 1u);
    double perimeter = 0.0;
    for (std::size_t i = 0; i < loops[0].size(); ++i)
      perimeter += (m.pattern[static_cast<std::size_t>(loops[0][(i + 1) % loops[0].size()])] -
                    m.pattern[static_cast<std::size_t>(loops[0][i])])
                       .norm();
    EXPECT_NEAR(perimeter, 0.16 + 2.0 * (to - start).norm(), 1e-12) << to.transpose();
    // The new tip is the outline's sharpest inward corner: a candidate.
    EXPECT_EQ(inwardCorners(m, 0.1), std::vector<int>{cut.tip});
  }
  mesh::SheetMesh m = mesh::makeRectangleSheet(0.04, 0.04, 0.005);
  EXPECT_THROW(cutAlong(m, mesh::nearestPatternVertex(m, Vec2(0.02, 0.02)), Vec2(0.02, 0.03)),
               std::invalid_argument)
      << "from an interior vertex";
  EXPECT_THROW(cutAlong(m, mesh::nearestPatternVertex(m, Vec2(0.02, 0.0)), Vec2(0.02, -0.01)),
               std::invalid_argument)
      << "out of the sheet at once";
}

TEST(Cut, ACutThroughTheSheetLeavesTwoPiecesAndBlendsItsNewVertices) {
  mesh::SheetMesh m = mesh::makeRectangleSheet(0.04, 0.04, 0.005);
  // A sheet in a gentle bowl, moving: every vertex has a position and a
  // velocity that new vertices must reproduce by their blends.
  std::vector<Vec3> velocity;
  for (auto& x : m.positions) x.z() = 3.0 * (x.x() * x.x() + x.y() * x.y());
  for (const auto& x : m.positions) velocity.push_back(Vec3(x.y(), -x.x(), 2.0 * x.x()));
  const std::size_t before = m.vertexCount();
  const std::vector<Vec2> patternBefore = m.pattern;
  const int from = mesh::nearestPatternVertex(m, Vec2(0.02, 0.0));
  const CutResult cut = cutAlong(m, from, Vec2(0.0213, 0.06), CutOptions{0.2});
  EXPECT_FALSE(cut.relocated.empty()) << "vertices near the cut moved onto it";
  EXPECT_EQ(mesh::validate(m), "");
  EXPECT_TRUE(cut.separated);
  EXPECT_EQ(cut.twins.size(), cut.chain.size());
  EXPECT_NEAR(m.pattern[static_cast<std::size_t>(cut.tip)].y(), 0.04, 1e-12) << "ends on the edge";
  ASSERT_EQ(cut.blends.size(), m.vertexCount() - before);
  std::vector<std::pair<int, VertexBlend>> all = cut.relocated;
  for (std::size_t k = 0; k < cut.blends.size(); ++k)
    all.emplace_back(static_cast<int>(before + k), cut.blends[k]);
  for (const auto& [vertex, b] : all) {
    Vec2 pattern = Vec2::Zero();
    Vec3 v = Vec3::Zero();
    double sum = 0.0;
    for (int j = 0; j < 3; ++j) {
      if (b.vertex[static_cast<std::size_t>(j)] < 0) continue;
      ASSERT_LT(static_cast<std::size_t>(b.vertex[static_cast<std::size_t>(j)]), before);
      const double w = b.weight[static_cast<std::size_t>(j)];
      pattern += w * patternBefore[static_cast<std::size_t>(b.vertex[static_cast<std::size_t>(j)])];
      v += w * velocity[static_cast<std::size_t>(b.vertex[static_cast<std::size_t>(j)])];
      sum += w;
    }
    EXPECT_NEAR(sum, 1.0, 1e-12);
    const Vec2 q = m.pattern[static_cast<std::size_t>(vertex)];
    EXPECT_TRUE(pattern.isApprox(q, 1e-12));
    // Moved vertices are on the cut, nearer its line than they were.
    if (static_cast<std::size_t>(vertex) < before) {
      EXPECT_NE(std::find(cut.chain.begin(), cut.chain.end(), vertex), cut.chain.end());
      const auto off = [](const Vec2& x) { return std::abs(x.x() - 0.02 - x.y() / 0.06 * 0.0013); };
      EXPECT_LT(off(q), off(patternBefore[static_cast<std::size_t>(vertex)]));
    }
    // The velocity field is linear in the pattern: blending is exact.
    EXPECT_TRUE(v.isApprox(Vec3(q.y(), -q.x(), 2.0 * q.x()), 1e-9));
  }
  // Two pieces: two boundary loops, each closed, and no triangle of one
  // piece shares a vertex with the other.
  const auto loops = boundaryLoops(m);
  ASSERT_EQ(loops.size(), 2u);
  // Snapping kept every triangle well shaped: no angle below 5 degrees
  // (the criss-cross grid's smallest is 45).
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) {
      const Vec2 a = m.pattern[static_cast<std::size_t>(t[static_cast<std::size_t>(k)])];
      const Vec2 b = m.pattern[static_cast<std::size_t>(t[static_cast<std::size_t>((k + 1) % 3)])];
      const Vec2 c = m.pattern[static_cast<std::size_t>(t[static_cast<std::size_t>((k + 2) % 3)])];
      const double angle =
          std::acos(std::clamp((b - a).normalized().dot((c - a).normalized()), -1.0, 1.0));
      EXPECT_GT(angle, 5.0 * std::numbers::pi / 180.0);
    }
}

}  // namespace
}  // namespace crumple::tear

namespace crumple::tear {
namespace {

TEST(Cut, ATearGoesOnFromItsTipTurningEitherWay) {
  for (const double turn : {-0.1, 0.0, 0.1, -0.6, 0.6}) {
    mesh::SheetMesh m = mesh::makeRectangleSheet(0.21, 0.297, 0.005);
    const int from = mesh::nearestPatternVertex(m, Vec2(0.1, 0.0));
    const CutResult first = cutAlong(m, from, Vec2(0.1, 0.02));
    const Vec2 tip = m.pattern[static_cast<std::size_t>(first.tip)];
    const Vec2 to = tip + 0.02 * Vec2(std::sin(-turn), std::cos(turn));
    CutResult second;
    EXPECT_NO_THROW(second = cutAlong(m, first.tip, to)) << "turn " << turn;
    EXPECT_EQ(mesh::validate(m), "") << "turn " << turn;
    EXPECT_TRUE(m.pattern[static_cast<std::size_t>(second.tip)].isApprox(to, 1e-12)) << turn;
    EXPECT_EQ(boundaryLoops(m).size(), 1u);
  }
}

}  // namespace
}  // namespace crumple::tear

namespace crumple::tear {
namespace {

// The candidates of a Tearing whose one tear went from the bottom edge's
// middle up 1 cm, then `turn` rad to the left for another cm (replayed),
// with no forces anywhere.
std::vector<TearCandidate> candidatesAfterATurn(double turn) {
  mesh::SheetMesh m = mesh::makeRectangleSheet(0.04, 0.04, 0.005);
  Tearing tearing(m, TearingParams{}, 1);
  const std::vector<char> held(m.vertexCount(), 0);
  TearEvent start;
  start.started = true;
  start.tear = 0;
  start.kind = CandidateKind::InwardCorner;
  start.from = Vec2(0.02, 0.0);
  start.to = Vec2(0.02, 0.01);
  TearEvent on = start;
  on.started = false;
  on.from = start.to;
  on.to = start.to + 0.01 * Vec2(-std::sin(turn), std::cos(turn));
  const TearFrameResult made = tearing.replay(m, {start, on}, held);
  EXPECT_EQ(made.events.size(), 2u);
  std::vector<char> none(m.vertexCount(), 0);
  const TearFrameResult next =
      tearing.step(m, {}, none, [](int) { return std::vector<TriangleForce>{}; });
  std::vector<TearCandidate> out;
  for (const auto& t : next.tests) out.push_back(t.candidate);
  return out;
}

TEST(Tearing, ATearMayBranchWhereItTurnedMoreThanEpsA) {
  // Straight on: the former tip is part of the lips, only the tip is a candidate.
  const auto straight = candidatesAfterATurn(0.0);
  ASSERT_EQ(straight.size(), 1u);
  EXPECT_EQ(straight[0].kind, CandidateKind::Tip);
  // A 0.5 rad turn (> eps_a = 0.1): the former tip's copy on the outside of
  // the turn is an inward corner of the outline, a candidate to branch from.
  const auto turned = candidatesAfterATurn(0.5);
  ASSERT_EQ(turned.size(), 2u);
  int tips = 0, corners = 0;
  for (const auto& c : turned) {
    tips += c.kind == CandidateKind::Tip ? 1 : 0;
    corners += c.kind == CandidateKind::InwardCorner ? 1 : 0;
  }
  EXPECT_EQ(tips, 1);
  EXPECT_EQ(corners, 1);
  // Below eps_a (0.05 rad), no branch point.
  EXPECT_EQ(candidatesAfterATurn(0.05).size(), 1u);
}

}  // namespace
}  // namespace crumple::tear
