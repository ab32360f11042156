// Render-time refinement of curved regions (crumple/mesh/developable.hpp) on
// S_P-like strips made by hand: a sheet folded at its rulings like the
// crumpling model's S_P (every cell exactly at pattern lengths), and a cone.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>

#include "crumple/mesh/developable.hpp"

using namespace crumple;
using namespace crumple::mesh;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// A 10 x 5 cm sheet: a flat cell [0, 2] cm, six 1 cm curved quads (split at
// their barycentre, as S_P splits them), a flat cell [8, 10] cm. Rulings run
// across y; the cross-section turns by `turn` at every ruling, so every
// triangle keeps its pattern shape (S_P's chords at pattern length).
struct Strip {
  SheetMesh mesh;
  DevelopableStructure structure;
  std::vector<int> flatTriangles;
};

Strip foldedStrip(double turn, int quads = 6) {
  Strip s;
  SheetMesh& m = s.mesh;
  const double h = 0.05;
  std::vector<double> xs{0.0};
  for (int k = 0; k <= quads; ++k) xs.push_back(0.02 + 0.01 * k);
  xs.push_back(0.04 + 0.01 * quads);
  // Cross-section: x -> (X, Z), turning by `turn` at each ruling x_1 .. x_{n-1}.
  std::vector<Vec2> section{Vec2::Zero()};
  double angle = 0.0;
  for (std::size_t i = 1; i < xs.size(); ++i) {
    section.push_back(section.back() +
                      (xs[i] - xs[i - 1]) * Vec2(std::cos(angle), std::sin(angle)));
    angle += turn;
  }
  const auto place = [&](double x, double y) {
    std::size_t i = 0;
    while (i + 2 < xs.size() && x > xs[i + 1]) ++i;
    const Vec2 d = (section[i + 1] - section[i]) / (xs[i + 1] - xs[i]);
    const Vec2 p = section[i] + (x - xs[i]) * d;
    return Vec3(p.x(), y, p.y());
  };
  const auto vertex = [&](double x, double y) {
    m.pattern.emplace_back(x, y);
    m.positions.push_back(place(x, y));
    return static_cast<int>(m.pattern.size()) - 1;
  };
  std::vector<int> bottom, top;
  for (double x : xs) {
    bottom.push_back(vertex(x, 0.0));
    top.push_back(vertex(x, h));
  }
  m.regionTypes = {RegionType::Flat, RegionType::Curved, RegionType::Flat};
  const auto add = [&](std::array<int, 3> t, int region) {
    if (region != 1) s.flatTriangles.push_back(static_cast<int>(m.triangles.size()));
    m.triangles.push_back(t);
    m.regionOfTriangle.push_back(region);
  };
  const std::size_t last = xs.size() - 1;
  add({bottom[0], bottom[1], top[1]}, 0);
  add({bottom[0], top[1], top[0]}, 0);
  CurvedRegion curved;
  curved.region = 1;
  for (std::size_t k = 1; k < last; ++k) curved.rulings.push_back({bottom[k], top[k]});
  for (std::size_t k = 1; k + 1 < last; ++k) {
    const double xm = 0.5 * (xs[k] + xs[k + 1]);
    // The barycentre of the planar quad, where S_P puts it.
    m.pattern.emplace_back(xm, 0.5 * h);
    m.positions.push_back(place(xm, 0.5 * h));
    const int c = static_cast<int>(m.pattern.size()) - 1;
    add({bottom[k], bottom[k + 1], c}, 1);
    add({bottom[k + 1], top[k + 1], c}, 1);
    add({top[k + 1], top[k], c}, 1);
    add({top[k], bottom[k], c}, 1);
  }
  add({bottom[last - 1], bottom[last], top[last]}, 2);
  add({bottom[last - 1], top[last], top[last - 1]}, 2);
  s.structure.regions.push_back(curved);
  return s;
}

// The largest dihedral angle across the inner edges of the given triangles.
double largestDihedral(const SheetMesh& m, const std::vector<int>& triangles) {
  std::map<std::pair<int, int>, std::vector<int>> edges;
  for (int t : triangles)
    for (int k = 0; k < 3; ++k) {
      const int a = m.triangles[t][k], b = m.triangles[t][(k + 1) % 3];
      edges[{std::min(a, b), std::max(a, b)}].push_back(t);
    }
  const auto normal = [&](int t) {
    const auto& tri = m.triangles[t];
    return Vec3((m.positions[tri[1]] - m.positions[tri[0]])
                    .cross(m.positions[tri[2]] - m.positions[tri[0]])
                    .normalized());
  };
  double worst = 0.0;
  for (const auto& [e, ts] : edges)
    if (ts.size() == 2)
      worst = std::max(worst, std::acos(std::clamp(normal(ts[0]).dot(normal(ts[1])), -1.0, 1.0)));
  return worst;
}

std::vector<int> newTriangles(const RefinedSheet& r) {
  std::vector<int> out;
  for (std::size_t t = 0; t < r.sourceOfTriangle.size(); ++t)
    if (r.sourceOfTriangle[t] < 0) out.push_back(static_cast<int>(t));
  return out;
}

}  // namespace

TEST(Developable, AFoldedStripBecomesSmoothAndStaysIsometric) {
  const Strip s = foldedStrip(22.0 * kDeg);
  ASSERT_LT(meanLengthError(s.mesh), 1e-12);
  const RefinedSheet r = refineDevelopable(s.mesh, s.structure, RefineOptions{});
  EXPECT_EQ(r.stats.runs, 1) << "skipped faces " << r.stats.skippedFaces;
  EXPECT_EQ(r.stats.refinedRuns, 1);
  EXPECT_EQ(r.stats.guardedRuns, 0);
  // The source folds by 22 degrees at each ruling; refined, no sub-cell by
  // more than 1.8 degrees (RefineOptions::maxAngle).
  std::vector<int> sourceCurved;
  for (std::size_t t = 0; t < s.mesh.triangleCount(); ++t)
    if (s.mesh.regionOfTriangle[t] == 1) sourceCurved.push_back(static_cast<int>(t));
  EXPECT_GT(largestDihedral(s.mesh, sourceCurved), 10.0 * kDeg);
  EXPECT_LE(largestDihedral(r.mesh, newTriangles(r)), 1.8 * kDeg + 1e-9);
  EXPECT_LE(r.stats.largestFold, 1.8 * kDeg);
  EXPECT_LE(meanLengthError(r.mesh), 1e-4);
  // Flat triangles, and the run's border rulings, are the source's bit for bit.
  for (int t : s.flatTriangles) {
    const int rt = r.triangleOfSource[t];
    ASSERT_GE(rt, 0);
    EXPECT_EQ(r.mesh.triangles[rt], s.mesh.triangles[t]);
    for (int v : s.mesh.triangles[t]) EXPECT_EQ(r.mesh.positions[v], s.mesh.positions[v]);
  }
  // Each refined triangle is counter-clockwise in the pattern.
  for (int t : newTriangles(r)) {
    const auto& tri = r.mesh.triangles[t];
    const Vec2 e1 = r.mesh.pattern[tri[1]] - r.mesh.pattern[tri[0]];
    const Vec2 e2 = r.mesh.pattern[tri[2]] - r.mesh.pattern[tri[0]];
    EXPECT_GT(e1.x() * e2.y() - e1.y() * e2.x(), 0.0);
  }
}

TEST(Developable, OffAndFixedModes) {
  const Strip s = foldedStrip(15.0 * kDeg);
  RefineOptions off;
  off.mode = RefineMode::Off;
  const RefinedSheet same = refineDevelopable(s.mesh, s.structure, off);
  EXPECT_EQ(same.mesh.triangles, s.mesh.triangles);
  EXPECT_EQ(same.mesh.positions, s.mesh.positions);
  RefineOptions fixed;
  fixed.mode = RefineMode::Fixed;
  fixed.cells = 5;
  const RefinedSheet r = refineDevelopable(s.mesh, s.structure, fixed);
  // Six quads of five cells, two triangles each.
  EXPECT_EQ(newTriangles(r).size(), 6u * 5u * 2u);
  EXPECT_EQ(r.stats.largestCells, 5);
}

namespace {

// A fan of `faces` triangles from an apex at the pattern origin to a
// straight side (a generalized cone, paper Sec. 3.2), folded by `turn` at each inner ruling
// so that every triangle keeps its pattern shape; one flat triangle beyond
// each end ruling.
Strip foldedFan(double turn, int faces = 8) {
  Strip s;
  SheetMesh& m = s.mesh;
  // The apex 6 cm from a straight side of the sheet (a d-cone's fan reaches
  // the sheet's outline, straight in the pattern).
  m.pattern.push_back(Vec2::Zero());
  for (int k = 0; k <= faces + 2; ++k) m.pattern.emplace_back(0.05 - 0.1 * k / (faces + 2), 0.06);
  // Rigid motions of the pattern, each folded from the last about their ruling.
  m.positions.assign(m.pattern.size(), Vec3::Zero());
  Mat3 R = Mat3::Identity();
  for (int k = 0; k <= faces + 2; ++k) {
    const Vec3 p(m.pattern[k + 1].x(), m.pattern[k + 1].y(), 0.0);
    m.positions[k + 1] = R * p;
    if (k >= 1 && k <= faces + 1) {
      const Vec3 axis = m.positions[k + 1].normalized();
      R = Eigen::AngleAxisd(turn, axis).toRotationMatrix() * R;
    }
  }
  m.regionTypes = {RegionType::Flat, RegionType::Curved, RegionType::Flat};
  CurvedRegion fan;
  fan.region = 1;
  fan.apex = 0;
  for (int k = 0; k <= faces + 1; ++k) {
    const int region = k == 0 ? 0 : k == faces + 1 ? 2 : 1;
    if (region != 1) s.flatTriangles.push_back(static_cast<int>(m.triangles.size()));
    m.triangles.push_back({0, k + 1, k + 2});
    m.regionOfTriangle.push_back(region);
    if (k >= 1) fan.rulings.push_back({0, k + 1});  // (0, 2) .. (0, faces + 2)
  }
  s.structure.regions.push_back(fan);
  return s;
}

}  // namespace

TEST(Developable, AConeFansFromItsApexWhichStaysPut) {
  const Strip s = foldedFan(20.0 * kDeg);
  ASSERT_EQ(s.structure.regions[0].rulings.size(), 9u);
  ASSERT_EQ(validate(s.structure, s.mesh), "");
  ASSERT_LT(meanLengthError(s.mesh), 1e-12);
  const RefinedSheet r = refineDevelopable(s.mesh, s.structure, RefineOptions{});
  EXPECT_EQ(r.stats.refinedRuns, 1)
      << r.stats.runs << " runs, " << r.stats.skippedFaces << " faces skipped, "
      << r.stats.roughRuns << " rough, " << r.stats.guardedRuns << " guarded";
  EXPECT_LE(r.stats.largestFold, 1.8 * kDeg);
  EXPECT_LE(largestDihedral(r.mesh, newTriangles(r)), 1.8 * kDeg + 1e-9);
  EXPECT_LE(meanLengthError(r.mesh), 1e-4);
  EXPECT_EQ(r.mesh.positions[0], s.mesh.positions[0]) << "the apex, bit for bit";
  for (int t : newTriangles(r)) EXPECT_EQ(r.mesh.triangles[t][0], 0) << "every sub-cell fans";
}

TEST(Developable, PinnedEndsAndLockedTrianglesSplitTheRuns) {
  const Strip s = foldedStrip(22.0 * kDeg);
  const auto& rulings = s.structure.regions[0].rulings;
  // A handle on the bottom end of the fourth ruling: runs on both sides.
  const std::vector<int> pinned{rulings[3][0]};
  const RefinedSheet p = refineDevelopable(s.mesh, s.structure, RefineOptions{}, pinned);
  EXPECT_EQ(p.stats.runs, 2);
  EXPECT_EQ(p.mesh.positions[pinned[0]], s.mesh.positions[pinned[0]]);
  // A tear patch on a triangle of the third quad: it stays, the quads on
  // either side refine (runs of two and three faces).
  // (Triangles: two flat ones, then four per quad.)
  const std::vector<int> locked{2 + 4 * 2};
  const RefinedSheet r = refineDevelopable(s.mesh, s.structure, RefineOptions{}, {}, locked);
  EXPECT_EQ(r.stats.runs, 2);
  EXPECT_EQ(r.stats.skippedFaces, 1);
  const int kept = r.triangleOfSource[locked[0]];
  ASSERT_GE(kept, 0);
  EXPECT_EQ(r.mesh.triangles[kept], s.mesh.triangles[locked[0]]);
  TearAtlas atlas;
  atlas.width = atlas.height = 1;
  atlas.mask = {255};
  TearPatch patch;
  patch.triangle = locked[0];
  patch.polygon = {Vec2(0, 0), Vec2(1, 0), Vec2(0, 1)};
  atlas.patches = {patch};
  const TearAtlas moved = remapTearAtlas(atlas, r);
  EXPECT_EQ(moved.patches[0].triangle, kept);
  EXPECT_EQ(moved.mask, atlas.mask);
  patch.triangle = 2 + 4 * 3;  // a triangle of the fourth quad, refined away
  atlas.patches = {patch};
  EXPECT_THROW(remapTearAtlas(atlas, r), std::invalid_argument);
}

TEST(Developable, ABadStructureIsRejected) {
  Strip s = foldedStrip(10.0 * kDeg);
  DevelopableStructure bad = s.structure;
  bad.regions[0].region = 0;
  EXPECT_NE(validate(bad, s.mesh), "") << "a flat region";
  bad = s.structure;
  bad.regions[0].rulings[2][1] = 999;
  EXPECT_NE(validate(bad, s.mesh), "");
  EXPECT_THROW(refineDevelopable(s.mesh, bad, RefineOptions{}), std::invalid_argument);
  bad = s.structure;
  bad.regions[0].rulings.resize(1);
  EXPECT_NE(validate(bad, s.mesh), "");
}
