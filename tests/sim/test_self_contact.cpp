// Self-contact of the sheet: the FCL broad phase and the
// exact vertex-triangle narrow phase, the fold gate, and a flap that falls
// onto its own sheet in the elastic step.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <numbers>

#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/sim/colliders.hpp"
#include "crumple/sim/elastic_sheet.hpp"
#include "crumple/sim/self_contact.hpp"

namespace crumple::sim {
namespace {

constexpr double kThickness = 1e-4;

// Two triangles far apart in the pattern, stacked `gap` apart in space
// (triangle 1 above triangle 0, both facing +Y).
struct Stack {
  std::vector<std::array<int, 3>> triangles{{0, 2, 1}, {3, 5, 4}};
  std::vector<Vec2> pattern{{0, 0}, {0.01, 0}, {0, 0.01}, {0.1, 0}, {0.11, 0}, {0.1, 0.01}};
  std::vector<Vec3> positions;
  explicit Stack(double gap) {
    positions = {{0, 0, 0},   {0.01, 0, 0},   {0, 0, 0.01},
                 {0, gap, 0}, {0.01, gap, 0}, {0, gap, 0.01}};
  }
};

TEST(SelfContact, FindsStackedLayersWithinTheReachAndOnlyThem) {
  const Stack near(0.5 * kThickness);
  SelfContactDetector detector(near.triangles, near.pattern, kThickness);
  const auto pairs = detector.find(near.positions, 2.0 * kThickness);
  ASSERT_EQ(pairs.size(), 6u) << "each corner over (or under) the other triangle";
  for (const auto& p : pairs) {
    EXPECT_NEAR(p.distance, 0.5 * kThickness, 1e-15);
    const bool upper = p.vertex >= 3;
    EXPECT_EQ(p.triangle, upper ? 0 : 1);
    EXPECT_TRUE(p.normal.isApprox(upper ? Vec3::UnitY() : Vec3(-Vec3::UnitY()), 1e-12))
        << "from the triangle toward the vertex";
    const double sum = p.weights[0] + p.weights[1] + p.weights[2];
    EXPECT_NEAR(sum, 1.0, 1e-12);
  }
  EXPECT_EQ(detector.broadPhasePairs(), 1u);
  // Refitted, not rebuilt: the same detector on layers 3 thicknesses apart.
  const Stack far(3.0 * kThickness);
  EXPECT_TRUE(detector.find(far.positions, 2.0 * kThickness).empty());
  // A mask leaves vertices out.
  std::vector<char> mask{1, 1, 1, 0, 0, 0};
  EXPECT_EQ(detector.find(near.positions, 2.0 * kThickness, &mask).size(), 3u);
}

TEST(SelfContact, FindsAnEdgeThatPassesThroughAnotherLayer) {
  // Triangle 1 stood upright (in the XY plane) with its corner 3 mm below
  // triangle 0 (the XZ plane), its edges 3-4 and 4-5 through it.
  Stack pierced(0.0);
  pierced.positions[3] = {0.004, -0.003, 0.004};
  pierced.positions[4] = {0.004, 0.01, 0.001};
  pierced.positions[5] = {0.004, 0.01, 0.007};
  SelfContactDetector detector(pierced.triangles, pierced.pattern, kThickness);
  const auto crossings = detector.crossings(pierced.positions);
  ASSERT_EQ(crossings.size(), 2u);
  EXPECT_EQ(crossings[0].a, 3);
  EXPECT_EQ(crossings[0].b, 4);
  EXPECT_EQ(crossings[1].a, 3);
  EXPECT_EQ(crossings[1].b, 5);
  for (const auto& c : crossings) {
    EXPECT_EQ(c.triangle, 0);
    EXPECT_NEAR(c.depth, 0.003, 1e-12) << "the shorter part, below the plane";
  }
  // Lifted 4 mm, the same triangle stands on the other one: no crossing,
  // and none when the two layers lie flat on each other.
  for (auto& x : {3, 4, 5}) pierced.positions[static_cast<std::size_t>(x)].y() += 0.004;
  EXPECT_TRUE(detector.crossings(pierced.positions).empty());
  EXPECT_TRUE(detector.crossings(Stack(0.5 * kThickness).positions).empty());
}

TEST(SelfContact, NeighboursInTheMaterialAreNotContacts) {
  // A flat sheet: every vertex is within reach of triangles around it, but
  // those share a vertex with its triangles or are material neighbours.
  mesh::SheetMesh m = mesh::makeRectangleSheet(0.05, 0.05, 0.005);
  mesh::placePattern(m, Vec3::Zero(), Vec3::UnitX(), -Vec3::UnitZ());
  SelfContactDetector detector(m.triangles, m.pattern, kThickness);
  EXPECT_TRUE(detector.find(m.positions, 2.0 * kThickness).empty());
  // The same with triangles much finer than the reach: the pattern exclusion
  // alone keeps in-plane neighbours out.
  mesh::SheetMesh fine = mesh::makeRectangleSheet(0.002, 0.002, 0.0002);
  mesh::placePattern(fine, Vec3::Zero(), Vec3::UnitX(), -Vec3::UnitZ());
  SelfContactDetector fineDetector(fine.triangles, fine.pattern, kThickness);
  EXPECT_TRUE(fineDetector.find(fine.positions, 2.0 * kThickness).empty());
  EXPECT_GT(fineDetector.broadPhasePairs(), 0u) << "the broad phase did see candidates";
}

TEST(SelfContact, TheFoldGateOpensWhenNormalsSpread) {
  mesh::SheetMesh m = mesh::makeRectangleSheet(0.1, 0.02, 0.01);
  mesh::placePattern(m, Vec3::Zero(), Vec3::UnitX(), -Vec3::UnitZ());
  const double spread = std::numbers::pi / 3.0;
  EXPECT_FALSE(sheetIsFolded(m.triangles, m.positions, spread)) << "flat";
  // Bent around the Z axis by a total angle: a 90 degree bend spreads the
  // normals by 45 degrees from their mean, a 180 degree fold by 90.
  const auto bent = [&](double total) {
    std::vector<Vec3> x = m.positions;
    const double radius = 0.1 / total;
    for (std::size_t i = 0; i < x.size(); ++i) {
      const double a = m.pattern[i].x() / radius;
      x[i] = Vec3(radius * std::sin(a), radius * (1.0 - std::cos(a)), -m.pattern[i].y());
    }
    return x;
  };
  EXPECT_FALSE(sheetIsFolded(m.triangles, bent(0.5 * std::numbers::pi), spread));
  EXPECT_TRUE(sheetIsFolded(m.triangles, bent(std::numbers::pi), spread));
}

// Two 5 x 5 cm pieces of one sheet (apart in the pattern, as after a fold
// far away): the lower one one thickness over a table (held there), the
// upper one `height` above it.
mesh::SheetMesh stackedPieces(double height) {
  mesh::SheetMesh lower = mesh::makeRectangleSheet(0.05, 0.05, 0.005);
  mesh::placePattern(lower, Vec3(0, kThickness, 0), Vec3::UnitX(), -Vec3::UnitZ());
  mesh::SheetMesh m = lower;
  const auto offset = static_cast<int>(lower.vertexCount());
  for (std::size_t i = 0; i < lower.vertexCount(); ++i) {
    m.pattern.push_back(lower.pattern[i] + Vec2(0.2, 0.0));
    // Shifted by a third of a cell, so no vertex sits over a vertex.
    m.positions.push_back(lower.positions[i] + Vec3(0.0017, height, -0.0013));
  }
  for (const auto& t : lower.triangles) {
    m.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
    m.regionOfTriangle.push_back(0);
  }
  return m;
}

struct Landing {
  double nearest = 1.0;  // the upper piece's vertices' least distance to the lower piece (m)
  double lowest = 1.0;   // the upper piece's lowest height over the table, over the lower piece
  double slid = 0.0;     // how far the upper piece's first vertex moved along X (m)
  long selfSteps = 0;
  double selfMs = 0.0;
};

// Drops the upper piece (with a sideways speed `vx`) for `seconds`.
Landing dropUpperPiece(SelfContactMode mode, double vx, double mu, double seconds) {
  Material paper;
  paper.thickness = kThickness;
  const mesh::SheetMesh m = stackedPieces(0.005);
  const std::size_t half = m.vertexCount() / 2;
  ElasticSheet sheet(m, paper, SimParams{});
  std::vector<Vec3> v(m.vertexCount(), Vec3::Zero());
  for (std::size_t i = half; i < v.size(); ++i) v[i] = Vec3(vx, -0.3, 0);
  sheet.setVelocities(v);
  ColliderSet table;
  table.add("table", ColliderShape{}, Pose{}, 0.0);  // frictionless: only paper on paper holds
  ContactOptions options;
  options.colliders = &table;
  options.distance = kThickness;
  options.self = mode;
  options.selfFriction = mu;
  sheet.setContacts(options);
  const double dt = 1.0 / 192.0;
  const PinFunction holdLower = [&m, half](double, std::vector<Pin>& out) {
    out.clear();
    for (std::size_t i = 0; i < half; ++i) out.push_back({static_cast<int>(i), m.positions[i]});
  };
  // The distance of the upper piece to the lower one, measured exactly.
  std::vector<char> upper(m.vertexCount(), 0);
  std::fill(upper.begin() + static_cast<std::ptrdiff_t>(half), upper.end(), 1);
  SelfContactDetector probe(m.triangles, m.pattern, kThickness);
  Landing out;
  const double x0 = m.positions[half].x();
  for (int step = 0; step < static_cast<int>(seconds / dt); ++step) {
    const StepStats stats = sheet.advance(step * dt, dt, holdLower);
    for (const auto& p : probe.find(sheet.positions(), 2.0 * kThickness, &upper))
      if (static_cast<std::size_t>(p.triangle) < m.triangles.size() / 2)
        out.nearest = std::min(out.nearest, p.distance);
    out.selfSteps += stats.selfContactSteps;
    out.selfMs += stats.selfContactMs;
    for (std::size_t i = half; i < m.vertexCount(); ++i) {
      const Vec3& x = sheet.positions()[i];
      if (x.x() > 0.0 && x.x() < 0.05 && x.z() < 0.0 && x.z() > -0.05)  // over the lower piece
        out.lowest = std::min(out.lowest, x.y());
    }
  }
  out.slid = sheet.positions()[half].x() - x0;
  return out;
}

TEST(SelfContact, APieceDroppedOntoAnotherPieceOfTheSheetStaysOnTop) {
  const Landing on = dropUpperPiece(SelfContactMode::On, 0.0, 0.3, 0.25);
  std::cout << "[ measure ] upper piece: nearest " << on.nearest / kThickness
            << " thicknesses from the lower piece, lowest " << on.lowest / kThickness
            << " over the table (lower piece at 1); self-contact " << on.selfMs << " ms over "
            << on.selfSteps << " steps\n";
  EXPECT_EQ(on.selfSteps, 48);
  EXPECT_GE(on.nearest, 0.9 * kThickness) << "no deeper than 10 % into the lower piece";
  EXPECT_GE(on.lowest, 1.9 * kThickness) << "on top of it, not through it";
  EXPECT_LE(on.lowest, 2.5 * kThickness) << "and resting on it";
  // Without self-contact it falls into the lower piece (the table stops
  // it); "auto" sees two flat pieces, no fold, and does the same.
  const Landing off = dropUpperPiece(SelfContactMode::Off, 0.0, 0.3, 0.25);
  EXPECT_EQ(off.selfSteps, 0);
  EXPECT_LT(off.lowest, 1.5 * kThickness);
  const Landing gate = dropUpperPiece(SelfContactMode::Auto, 0.0, 0.3, 0.25);
  EXPECT_EQ(gate.selfSteps, 0);
}

TEST(SelfContact, PaperOnPaperFrictionSlowsASlidingPiece) {
  // Thrown sideways at 0.2 m/s onto the lower piece: with paper-on-paper
  // friction 0.3 it stops within v^2 / (2 mu g) = 6.8 mm; without friction
  // it keeps going.
  const Landing rough = dropUpperPiece(SelfContactMode::On, 0.2, 0.3, 0.2);
  const Landing smooth = dropUpperPiece(SelfContactMode::On, 0.2, 0.0, 0.2);
  std::cout << "[ measure ] slid " << rough.slid << " m (mu 0.3), " << smooth.slid
            << " m (mu 0) in 0.2 s\n";
  EXPECT_GE(rough.nearest, 0.9 * kThickness);
  EXPECT_GE(smooth.nearest, 0.9 * kThickness);
  EXPECT_LT(rough.slid, 0.025);
  EXPECT_GT(smooth.slid, 0.035);
}

}  // namespace
}  // namespace crumple::sim
