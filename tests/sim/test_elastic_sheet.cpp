// ElasticSheet integration tests (paper Sec. 4): a hanging A4 sheet comes to
// rest, determinism across thread counts, hard handle constraints, failure
// handling and reuse of the symbolic factorisation.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>

#include "crumple/core/error.hpp"
#include "crumple/core/parallel.hpp"
#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/sim/elastic_sheet.hpp"
#include "crumple/sim/energies.hpp"

using namespace crumple;
using namespace crumple::sim;

namespace {

// The 70 g/m^2 office preset.
Material officePaper() { return Material{}; }  // the office-70gsm preset

constexpr double kWidth = 0.21, kHeight = 0.297;

// An A4 sheet in a vertical plane, tilted by `tilt` rad about its top edge
// (tilt 0: the plane z = 0, gravity -y in the plane). Pattern v points up.
mesh::SheetMesh a4Sheet(double tilt, double maxEdge = 0.021) {
  mesh::SheetMesh m = mesh::makeRectangleSheet(kWidth, kHeight, maxEdge);
  const Vec3 vAxis(0.0, std::cos(tilt), std::sin(tilt));
  mesh::placePattern(m, Vec3(0.0, 0.0, 0.0) - kHeight * vAxis, Vec3::UnitX(), vAxis);
  return m;
}

// Pins for the two top corners at their initial positions.
PinFunction topCorners(const mesh::SheetMesh& m) {
  const int a = mesh::nearestPatternVertex(m, Vec2(0.0, kHeight));
  const int b = mesh::nearestPatternVertex(m, Vec2(kWidth, kHeight));
  const Vec3 pa = m.positions[static_cast<std::size_t>(a)];
  const Vec3 pb = m.positions[static_cast<std::size_t>(b)];
  return [=](double, std::vector<Pin>& out) {
    out.push_back({a, pa});
    out.push_back({b, pb});
  };
}

// Steps until the kinetic energy stays below `restEnergy` for 10 steps.
// Returns the number of steps (or maxSteps).
int runToRest(ElasticSheet& sheet, const PinFunction& pins, double dt, int maxSteps,
              double restEnergy) {
  int quiet = 0;
  for (int step = 0; step < maxSteps; ++step) {
    sheet.advance(step * dt, dt, pins);
    quiet = sheet.kineticEnergy() < restEnergy ? quiet + 1 : 0;
    if (quiet >= 10) return step + 1;
  }
  return maxSteps;
}

bool bitIdentical(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3)) == 0;
}

}  // namespace

TEST(ElasticSheet, HangingSheetComesToRest) {
  const mesh::SheetMesh m = a4Sheet(0.0);
  ElasticSheet sheet(m, officePaper(), SimParams{});
  const PinFunction pins = topCorners(m);
  const double dt = 1.0 / 96.0;
  const int steps = runToRest(sheet, pins, dt, 2000, 1e-9);
  RecordProperty("steps", steps);
  EXPECT_LT(steps, 2000);
  EXPECT_LT(sheet.kineticEnergy(), 1e-9);
  EXPECT_LT(sheet.maxMembraneStrain(), 0.01);
  EXPECT_EQ(sheet.analyzeCount(), 1);
  // It hangs: the bottom edge went down a little, nothing went up.
  const int bottom = mesh::nearestPatternVertex(m, Vec2(kWidth / 2, 0.0));
  EXPECT_LT(sheet.positions()[static_cast<std::size_t>(bottom)].y(),
            m.positions[static_cast<std::size_t>(bottom)].y());
  for (const Vec3& p : sheet.positions()) EXPECT_TRUE(p.allFinite());
}

TEST(ElasticSheet, TiltedHangingSheetSwingsToRest) {
  // Released 0.3 rad out of the vertical plane: it swings about the line
  // through the two pins and settles hanging straight down.
  const mesh::SheetMesh m = a4Sheet(0.3);
  ElasticSheet sheet(m, officePaper(), SimParams{});
  const PinFunction pins = topCorners(m);
  const double dt = 1.0 / 48.0;  // ~400 steps to rest; 1/96 takes ~1000 (both pass)
  double maxKinetic = 0.0;
  int steps = 0;
  int quiet = 0;
  for (; steps < 1500 && quiet < 10; ++steps) {
    sheet.advance(steps * dt, dt, pins);
    maxKinetic = std::max(maxKinetic, sheet.kineticEnergy());
    quiet = sheet.kineticEnergy() < 1e-9 ? quiet + 1 : 0;
  }
  RecordProperty("steps", steps);
  EXPECT_GT(maxKinetic, 1e-5);  // it really swung
  EXPECT_LT(sheet.kineticEnergy(), 1e-9);
  EXPECT_LT(sheet.maxMembraneStrain(), 0.01);
  // At rest the bottom-middle vertex hangs (almost) straight below the pins.
  const int bottom = mesh::nearestPatternVertex(m, Vec2(kWidth / 2, 0.0));
  const Vec3 p = sheet.positions()[static_cast<std::size_t>(bottom)];
  EXPECT_LT(std::abs(p.z()), 0.01);
  EXPECT_LT(p.y(), -0.25);
}

TEST(ElasticSheet, BitIdenticalForAnyThreadCount) {
  const mesh::SheetMesh m = a4Sheet(0.3);
  const PinFunction pins = topCorners(m);
  auto run = [&](int threads) {
    setThreadCount(threads);
    ElasticSheet sheet(m, officePaper(), SimParams{});
    for (int step = 0; step < 30; ++step) sheet.advance(step / 96.0, 1.0 / 96.0, pins);
    setThreadCount(1);
    return std::make_pair(sheet.positions(), sheet.velocities());
  };
  const auto one = run(1);
  const auto two = run(2);
  const auto three = run(3);
  EXPECT_TRUE(bitIdentical(one.first, two.first));
  EXPECT_TRUE(bitIdentical(one.second, two.second));
  EXPECT_TRUE(bitIdentical(one.first, three.first));
}

TEST(ElasticSheet, SupernodalPathIsBitIdenticalForAnyThreadCount) {
  // ~10 000 triangles: large enough for CHOLMOD's supernodal factorisation
  // (BLAS kernels), which must not make results depend on --threads.
  const mesh::SheetMesh m = a4Sheet(0.3, 0.005);
  const PinFunction pins = topCorners(m);
  auto run = [&](int threads) {
    setThreadCount(threads);
    ElasticSheet sheet(m, officePaper(), SimParams{});
    for (int step = 0; step < 2; ++step) sheet.advance(step / 384.0, 1.0 / 384.0, pins);
    setThreadCount(1);
    EXPECT_TRUE(sheet.supernodalFactorization());
    return sheet.positions();
  };
  const auto one = run(1);
  EXPECT_TRUE(bitIdentical(one, run(2)));
  // A small sheet stays on the simplicial path.
  ElasticSheet small(a4Sheet(0.3), officePaper(), SimParams{});
  small.advance(0.0, 1.0 / 384.0, topCorners(a4Sheet(0.3)));
  EXPECT_FALSE(small.supernodalFactorization());
}

TEST(ElasticSheet, PinsFollowAMovingTargetExactly) {
  const mesh::SheetMesh m = a4Sheet(0.0, 0.03);
  const int a = mesh::nearestPatternVertex(m, Vec2(0.0, kHeight));
  const int b = mesh::nearestPatternVertex(m, Vec2(kWidth, kHeight));
  const Vec3 pa = m.positions[static_cast<std::size_t>(a)];
  const Vec3 pb = m.positions[static_cast<std::size_t>(b)];
  auto target = [&](double t) {
    return Vec3(0.05 * std::sin(3.0 * t), 0.02 * t, 0.04 * (1 - std::cos(2.0 * t)));
  };
  const PinFunction pins = [&](double t, std::vector<Pin>& out) {
    out.push_back({a, pa + target(t)});
    out.push_back({b, pb + target(t)});
  };
  ElasticSheet sheet(m, officePaper(), SimParams{});
  const double dt = 1.0 / 96.0;
  for (int step = 0; step < 48; ++step) {
    const double t = step * dt;
    sheet.advance(t, dt, pins);
    const Vec3 ea = pa + target(t + dt), eb = pb + target(t + dt);
    ASSERT_EQ(sheet.positions()[static_cast<std::size_t>(a)], ea) << "step " << step;
    ASSERT_EQ(sheet.positions()[static_cast<std::size_t>(b)], eb) << "step " << step;
  }
  const Vec3 expectedVelocity = (target(48 * dt) - target(47 * dt)) / dt;
  EXPECT_LT((sheet.velocities()[static_cast<std::size_t>(a)] - expectedVelocity).norm(), 1e-12);
  EXPECT_EQ(sheet.analyzeCount(), 1);
}

// A grip holds a point inside a triangle, not a vertex: with the top corners
// pinned, a grip drawing the sheet's centre 3 cm out of its plane brings the
// gripped point there within the spring's give, and nothing is pinned there.
TEST(ElasticSheet, AGripDrawsAPointOfATriangleToItsTarget) {
  mesh::SheetMesh m = a4Sheet(0.0, 0.05);
  ElasticSheet sheet(m, officePaper(), SimParams{});
  // The triangle holding the pattern point (0.1, 0.15) and its weights.
  const auto [tri, w] = mesh::locatePattern(m, Vec2(0.1, 0.15));
  ASSERT_GE(tri, 0);
  const auto& T = m.triangles[static_cast<std::size_t>(tri)];
  const auto point = [&](const std::vector<Vec3>& x) {
    return Vec3(w(0) * x[static_cast<std::size_t>(T[0])] +
                w(1) * x[static_cast<std::size_t>(T[1])] +
                w(2) * x[static_cast<std::size_t>(T[2])]);
  };
  const Vec3 target = point(m.positions) + Vec3(0.0, 0.0, 0.03);
  constexpr double kStiffness = 200.0;  // N/m
  sheet.setGrips([&](double, std::vector<Grip>& out) {
    out.push_back({tri, w, target, kStiffness, -1});
  });
  runToRest(sheet, topCorners(m), 1.0 / 48.0, 200, 1e-7);
  // The spring's give: the weight of the sheet below it and its bending,
  // a few millimetres at most.
  const double miss = (point(sheet.positions()) - target).norm();
  EXPECT_LT(miss, 0.004);
  // Without the grip the point hangs in its plane.
  ElasticSheet free(m, officePaper(), SimParams{});
  runToRest(free, topCorners(m), 1.0 / 48.0, 200, 1e-7);
  EXPECT_LT(std::abs(point(free.positions()).z()), 1e-4);
  EXPECT_GT(point(sheet.positions()).z(), 0.025);
  // A grip on a missing triangle is a programming error.
  sheet.setGrips([&](double, std::vector<Grip>& out) {
    out.push_back({static_cast<int>(m.triangles.size()), w, target, kStiffness, -1});
  });
  EXPECT_THROW(sheet.advance(0.0, 0.01, topCorners(m)), std::out_of_range);
}

TEST(ElasticSheet, HopelessStepThrowsAndRestoresState) {
  const mesh::SheetMesh m = a4Sheet(0.3, 0.03);
  const PinFunction good = topCorners(m);
  ElasticSheet sheet(m, officePaper(), SimParams{});
  for (int step = 0; step < 5; ++step) sheet.advance(step / 96.0, 1.0 / 96.0, good);
  const std::vector<Vec3> x = sheet.positions(), v = sheet.velocities();

  const int a = mesh::nearestPatternVertex(m, Vec2(0.0, kHeight));
  const PinFunction bad = [&](double t, std::vector<Pin>& out) {
    good(t, out);
    out.push_back({a, Vec3(std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0)});
  };
  try {
    sheet.advance(5 / 96.0, 1.0 / 96.0, bad);
    FAIL() << "expected NumericalError";
  } catch (const NumericalError& e) {
    EXPECT_EQ(e.stage(), "elastic");
    EXPECT_NE(std::string(e.what()).find("non-finite pin"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(bitIdentical(sheet.positions(), x));
  EXPECT_TRUE(bitIdentical(sheet.velocities(), v));
  // And the sheet carries on afterwards.
  EXPECT_NO_THROW(sheet.advance(5 / 96.0, 1.0 / 96.0, good));
}

TEST(ElasticSheet, UnconvergedStepThrowsAfterHalvingAndRestoresState) {
  // One Newton iteration can never meet the tolerance from a cold predictor:
  // every level of halving fails and the state is restored.
  SimParams p;
  p.maxNewtonIterations = 1;
  p.maxHalvings = 3;
  const mesh::SheetMesh m = a4Sheet(0.3, 0.05);
  ElasticSheet sheet(m, officePaper(), p);
  EXPECT_THROW(sheet.advance(0.0, 1.0 / 96.0, topCorners(m)), NumericalError);
  EXPECT_TRUE(bitIdentical(sheet.positions(), m.positions));
  for (const Vec3& vel : sheet.velocities()) EXPECT_EQ(vel, Vec3::Zero());
}

TEST(ElasticSheet, LargeStepsAreRescuedByHalving) {
  // Few Newton iterations allowed, long steps and a fast jerk of the handles:
  // some steps have to be split, and the result is still a valid state with
  // the pins in place.
  SimParams p;
  p.maxNewtonIterations = 5;
  const mesh::SheetMesh m = a4Sheet(0.0, 0.03);
  const int a = mesh::nearestPatternVertex(m, Vec2(0.0, kHeight));
  const int b = mesh::nearestPatternVertex(m, Vec2(kWidth, kHeight));
  const Vec3 pa = m.positions[static_cast<std::size_t>(a)];
  const Vec3 pb = m.positions[static_cast<std::size_t>(b)];
  auto shift = [](double t) { return Vec3(0.0, 0.0, 0.5 * t); };  // 0.5 m/s out of plane
  const PinFunction pins = [&](double t, std::vector<Pin>& out) {
    out.push_back({a, pa + shift(t)});
    out.push_back({b, pb + shift(t)});
  };
  ElasticSheet sheet(m, officePaper(), p);
  int halvings = 0;
  const double dt = 1.0 / 24.0;
  for (int step = 0; step < 8; ++step) halvings += sheet.advance(step * dt, dt, pins).halvings;
  RecordProperty("halvings", halvings);
  EXPECT_GT(halvings, 0);
  EXPECT_EQ(sheet.positions()[static_cast<std::size_t>(a)], pa + shift(7 * dt + dt));
  for (const Vec3& q : sheet.positions()) EXPECT_TRUE(q.allFinite());
  EXPECT_LT(sheet.maxMembraneStrain(), 0.01);
}

TEST(ElasticSheet, CompressionFallsBackToPsdProjectedHessians) {
  // Pushing the top corners towards each other compresses and buckles the
  // sheet: the exact Hessian becomes indefinite, CHOLMOD rejects it and the
  // PSD-projected system is solved instead (an extra factorisation).
  const mesh::SheetMesh m = a4Sheet(0.0, 0.03);
  const int a = mesh::nearestPatternVertex(m, Vec2(0.0, kHeight));
  const int b = mesh::nearestPatternVertex(m, Vec2(kWidth, kHeight));
  const Vec3 pa = m.positions[static_cast<std::size_t>(a)];
  const Vec3 pb = m.positions[static_cast<std::size_t>(b)];
  const PinFunction pins = [&](double t, std::vector<Pin>& out) {
    const double d = 0.5 * t;
    out.push_back({a, pa + Vec3(d, 0.0, 0.3 * d)});
    out.push_back({b, pb - Vec3(d, 0.0, 0.0)});
  };
  ElasticSheet sheet(m, officePaper(), SimParams{});
  int newton = 0, solves = 0;
  for (int step = 0; step < 12; ++step) {
    const StepStats s = sheet.advance(step / 96.0, 1.0 / 96.0, pins);
    newton += s.newtonIterations;
    solves += s.solves;
  }
  EXPECT_GT(solves, newton);
  EXPECT_LT(sheet.maxMembraneStrain(), 0.01);
  EXPECT_GT(sheet.bendingEnergy(), 1e-4);  // it buckled out of plane
  for (const Vec3& q : sheet.positions()) EXPECT_TRUE(q.allFinite());
}

TEST(ElasticSheet, SymbolicAnalysisIsReusedWhileThePinSetIsUnchanged) {
  const mesh::SheetMesh m = a4Sheet(0.3, 0.03);
  ElasticSheet sheet(m, officePaper(), SimParams{});
  const PinFunction pins = topCorners(m);
  int solves = 0;
  for (int step = 0; step < 40; ++step)
    solves += sheet.advance(step / 96.0, 1.0 / 96.0, pins).solves;
  EXPECT_EQ(sheet.analyzeCount(), 1);
  EXPECT_GT(solves, 40);
  // A different pin set needs a new analysis, once.
  const int c = mesh::nearestPatternVertex(m, Vec2(kWidth / 2, kHeight));
  const PinFunction three = [&](double t, std::vector<Pin>& out) {
    pins(t, out);
    out.push_back({c, m.positions[static_cast<std::size_t>(c)]});
  };
  for (int step = 40; step < 50; ++step) sheet.advance(step / 96.0, 1.0 / 96.0, three);
  EXPECT_EQ(sheet.analyzeCount(), 2);
}

TEST(ElasticSheet, FreeFallIsExactWithoutDamping) {
  // An unstrained sheet falling freely moves rigidly: backward Euler gives
  // v = g t exactly and the Newton solve converges at once.
  SimParams p;
  p.massDamping = 0.0;
  const mesh::SheetMesh m = a4Sheet(0.7, 0.05);
  ElasticSheet sheet(m, officePaper(), p);
  const double dt = 0.01;
  for (int step = 0; step < 10; ++step) {
    const StepStats s = sheet.advance(step * dt, dt, PinFunction{});
    EXPECT_LE(s.newtonIterations, 2);
  }
  for (const Vec3& vel : sheet.velocities()) EXPECT_LT((vel - 0.1 * p.gravity).norm(), 1e-9);
  EXPECT_LT(sheet.maxMembraneStrain(), 1e-12);
  EXPECT_NEAR(sheet.kineticEnergy(),
              0.5 * officePaper().arealDensity() * kWidth * kHeight * std::pow(0.1 * 9.81, 2),
              1e-9);
}

namespace {

// Two triangles sharing the hinge 0-1 along the x axis, in the plane z = 0:
// wing 2 at (0.01, 0.015), wing 3 at `wing`.
mesh::SheetMesh twoTriangles(const Vec2& wing) {
  mesh::SheetMesh m;
  m.pattern = {Vec2(0, 0), Vec2(0.02, 0), Vec2(0.01, 0.015), wing};
  m.triangles = {{0, 1, 2}, {1, 0, 3}};
  m.regionOfTriangle = {0, 0};
  m.regionTypes = {mesh::RegionType::Flat};
  mesh::placePattern(m, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY());
  return m;
}

}  // namespace

TEST(ElasticSheet, HingeSettlesAtItsRestAngle) {
  // Two triangles: pin triangle A, let the wing vertex of B find the rest
  // angle (no gravity). Checks the sign convention end to end.
  const mesh::SheetMesh m = twoTriangles(Vec2(0.01, -0.015));
  SimParams p;
  p.gravity = Vec3::Zero();
  p.massDamping = 5.0;
  ElasticSheet sheet(m, officePaper(), p);
  ASSERT_EQ(sheet.hinges().size(), 1u);
  sheet.setHingeRestAngle(0, 0.6);
  EXPECT_EQ(sheet.hingeRestAngle(0), 0.6);
  const PinFunction pins = [&](double, std::vector<Pin>& out) {
    for (int i = 0; i < 3; ++i) out.push_back({i, m.positions[static_cast<std::size_t>(i)]});
  };
  for (int step = 0; step < 400; ++step) sheet.advance(step * 0.01, 0.01, pins);
  EXPECT_NEAR(sheet.hingeAngle(0), 0.6, 1e-6);
  // theta > 0: the wing went away from the normal side (+z).
  EXPECT_LT(sheet.positions()[3].z(), 0.0);
  EXPECT_LT(sheet.bendingEnergy(), 1e-15);
}

TEST(ElasticSheet, StiffnessDampingDissipates) {
  SimParams p;
  p.massDamping = 0.0;
  p.stiffnessDamping = 1e-3;
  const mesh::SheetMesh m = a4Sheet(0.3, 0.03);
  ElasticSheet sheet(m, officePaper(), p);
  const PinFunction pins = topCorners(m);
  for (int step = 0; step < 60; ++step) sheet.advance(step / 96.0, 1.0 / 96.0, pins);
  for (const Vec3& q : sheet.positions()) EXPECT_TRUE(q.allFinite());
  EXPECT_LT(sheet.maxMembraneStrain(), 0.01);
}

TEST(ElasticSheet, RejectsBadInput) {
  mesh::SheetMesh m = a4Sheet(0.0, 0.05);
  ElasticSheet sheet(m, officePaper(), SimParams{});
  EXPECT_THROW(sheet.setHingeStiffnessFactor(0, -1.0), std::invalid_argument);
  EXPECT_THROW(sheet.setHingeRestAngle(sheet.hinges().size(), 0.0), std::out_of_range);
  EXPECT_THROW(sheet.setPositions({}), std::invalid_argument);
  std::vector<Vec3> nan = m.positions;
  nan[3].y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(sheet.setPositions(nan), std::invalid_argument);
  EXPECT_THROW(sheet.setVelocities(nan), std::invalid_argument);
  EXPECT_THROW(sheet.advance(0.0, 0.0, PinFunction{}), std::invalid_argument);
  const PinFunction outOfRange = [](double, std::vector<Pin>& out) {
    out.push_back({100000, Vec3::Zero()});
  };
  EXPECT_THROW(sheet.advance(0.0, 0.01, outOfRange), std::out_of_range);
  Material bad = officePaper();
  bad.poissonRatio = 0.5;
  EXPECT_THROW(ElasticSheet(m, bad, SimParams{}), std::invalid_argument);
}

namespace {

// The hinge mesh of the stiffness tests below (two different wings, so that
// wing 3 never lands on wing 2 when it is rotated about the hinge).
mesh::SheetMesh twoTriangleHinge() { return twoTriangles(Vec2(0.008, -0.013)); }

// The mesh's positions with wing 3 rigidly rotated by `phi` about the hinge
// (the x axis), towards -z for phi > 0: the fold angle is phi.
std::vector<Vec3> foldedWing(const mesh::SheetMesh& m, double phi) {
  std::vector<Vec3> x = m.positions;
  const double y = m.positions[3].y();
  x[3] = Vec3(m.positions[3].x(), y * std::cos(phi), y * std::sin(phi));
  return x;
}

// The hinge stiffness k as ElasticSheet computes it (factor 1).
double twoTriangleHingeStiffness(const mesh::SheetMesh& m) {
  const auto& p = m.pattern;
  const double a0 = triangleRest(p[0], p[1], p[2]).area;
  const double a1 = triangleRest(p[1], p[0], p[3]).area;
  return hingeStiffness(officePaper().bendingStiffness(), 1.0, (p[1] - p[0]).squaredNorm(), a0, a1);
}

constexpr double kFoldStep = 0.1;  // rad per setPositions call
constexpr int kFoldSteps = 38;     // 3.8 rad, about 1.21 pi

}  // namespace

TEST(ElasticSheet, HingeAngleStaysContinuousWhenFoldedPastPi) {
  // Rotating one wing about the hinge in 0.1 rad steps up to ~1.2 pi: the
  // measured angle follows the rotation past pi (atan2 alone would jump to
  // -pi + ... and report ~ -0.8 pi at the end) and the bending energy keeps
  // growing as k theta^2 (on the wrapped branch it would fall again past pi).
  const mesh::SheetMesh m = twoTriangleHinge();
  ElasticSheet sheet(m, officePaper(), SimParams{});
  ASSERT_EQ(sheet.hinges().size(), 1u);
  const double k = twoTriangleHingeStiffness(m);
  ASSERT_GT(k, 0.0);
  EXPECT_NEAR(sheet.hingeAngle(0), 0.0, 1e-12);

  // Sign convention: wing towards -z is a positive fold.
  sheet.setPositions(foldedWing(m, 0.05));
  EXPECT_NEAR(sheet.hingeAngle(0), 0.05, 1e-9);

  double lastEnergy = sheet.bendingEnergy();
  for (int i = 1; i <= kFoldSteps; ++i) {
    const double phi = i * kFoldStep;
    sheet.setPositions(foldedWing(m, phi));
    ASSERT_NEAR(sheet.hingeAngle(0), phi, 1e-9) << "phi " << phi;
    const double energy = sheet.bendingEnergy();
    ASSERT_NEAR(energy, k * phi * phi, 1e-9 * k * phi * phi) << "phi " << phi;
    ASSERT_GT(energy, lastEnergy) << "phi " << phi;
    lastEnergy = energy;
  }
  EXPECT_GT(sheet.hingeAngle(0), 1.2 * std::numbers::pi);
  // A pure rotation about the hinge does not stretch anything.
  EXPECT_LT(sheet.maxMembraneStrain(), 1e-12);
}

TEST(ElasticSheet, HingeAngleIsRebasedBeyondOneAndAHalfTurnsOfPi) {
  // Wound on past 1.5 pi (a caller moving vertices step by step, as the
  // hybrid model's isometry does), the tracked angle is re-based by -2 pi
  // instead of growing by whole turns: after 2.5 turns it reads within
  // (-1.5 pi, 1.5 pi] and equals the rotation modulo 2 pi, with the energy
  // k theta^2 of that angle. Without the re-basing it would read 5 pi.
  const mesh::SheetMesh m = twoTriangleHinge();
  ElasticSheet sheet(m, officePaper(), SimParams{});
  const double k = twoTriangleHingeStiffness(m);
  const int steps = static_cast<int>(std::round(5.0 * std::numbers::pi / kFoldStep));
  double largest = 0.0;
  for (int i = 1; i <= steps; ++i) {
    sheet.setPositions(foldedWing(m, i * kFoldStep));
    largest = std::max(largest, std::abs(sheet.hingeAngle(0)));
  }
  EXPECT_LE(largest, 1.5 * std::numbers::pi + kFoldStep);
  EXPECT_GT(largest, 1.5 * std::numbers::pi - kFoldStep);  // it did follow past pi
  const double phi = steps * kFoldStep;
  const double expected = std::remainder(phi, 2.0 * std::numbers::pi);
  EXPECT_NEAR(sheet.hingeAngle(0), expected, 1e-9);
  EXPECT_NEAR(sheet.bendingEnergy(), k * expected * expected, 1e-9 * k * expected * expected);
}

TEST(ElasticSheet, HingeAngleUnwindsContinuouslyBackToFlat) {
  // Fold past pi, then rotate back down to flat and on to a small negative
  // fold: the angle retraces the rotation through pi and ends at 0 and then
  // -0.3 on the original branch, with the energy k theta^2 all the way.
  const mesh::SheetMesh m = twoTriangleHinge();
  ElasticSheet sheet(m, officePaper(), SimParams{});
  const double k = twoTriangleHingeStiffness(m);
  for (int i = 1; i <= kFoldSteps; ++i) sheet.setPositions(foldedWing(m, i * kFoldStep));
  ASSERT_NEAR(sheet.hingeAngle(0), kFoldSteps * kFoldStep, 1e-9);

  for (int i = kFoldSteps - 1; i >= -3; --i) {
    const double phi = i * kFoldStep;
    sheet.setPositions(foldedWing(m, phi));
    ASSERT_NEAR(sheet.hingeAngle(0), phi, 1e-9) << "phi " << phi;
    ASSERT_NEAR(sheet.bendingEnergy(), k * phi * phi, 1e-9 * k * phi * phi + 1e-20)
        << "phi " << phi;
  }
  sheet.setPositions(m.positions);
  EXPECT_NEAR(sheet.hingeAngle(0), 0.0, 1e-12);
  EXPECT_LT(sheet.bendingEnergy(), 1e-20);
}

TEST(ElasticSheet, HingeFoldedPastPiUnfoldsTheWayItCame) {
  // Folded to ~1.2 pi (rest angle 0) and released with triangle A pinned:
  // the bending force pulls the wing back through pi, across the -z side
  // (0 < theta < pi) to flat. With the wrapped angle (~ -0.8 pi) the force
  // would point the other way and the wing would finish the turn through
  // the +z side to 2 pi instead.
  const mesh::SheetMesh m = twoTriangleHinge();
  SimParams p;
  p.gravity = Vec3::Zero();
  p.massDamping = 5.0;
  ElasticSheet sheet(m, officePaper(), p);
  for (int i = 1; i <= kFoldSteps; ++i) sheet.setPositions(foldedWing(m, i * kFoldStep));
  ASSERT_GT(sheet.hingeAngle(0), std::numbers::pi);
  const PinFunction pins = [&](double, std::vector<Pin>& out) {
    for (int i = 0; i < 3; ++i) out.push_back({i, m.positions[static_cast<std::size_t>(i)]});
  };
  // Short steps first, so the path can be followed, then long ones to rest.
  const double start = sheet.hingeAngle(0);
  double minZ = sheet.positions()[3].z();
  double lastAngle = start;
  double t = 0.0;
  for (int step = 0; step < 300; ++step) {
    const double dt = step < 200 ? 2e-4 : 1e-2;
    sheet.advance(t, dt, pins);
    t += dt;
    minZ = std::min(minZ, sheet.positions()[3].z());
    const double angle = sheet.hingeAngle(0);
    // First it folds back towards pi (not on towards 2 pi) ...
    if (step == 0) {
      EXPECT_LT(angle, start);
      EXPECT_GT(angle, std::numbers::pi);
    }
    // ... and the measured angle never jumps by a branch.
    ASSERT_LT(std::abs(angle - lastAngle), 0.5) << "step " << step;
    lastAngle = angle;
  }
  EXPECT_LT(minZ, -0.01);  // it swept through the -z half-space (|y_3| = 0.013)
  EXPECT_NEAR(sheet.hingeAngle(0), 0.0, 1e-6);
  EXPECT_LT(sheet.bendingEnergy(), 1e-15);
}

// Tearing (thesis 3.3.3): the membrane force of each triangle on a
// vertex is minus its energy gradient; summed, they are minus the sheet's
// membrane energy gradient at that vertex (checked by central differences),
// and a sheet stretched along X pulls its right edge back to the left.
TEST(ElasticSheet, MembraneForcesOnAVertexAreMinusTheEnergyGradient) {
  mesh::SheetMesh m = mesh::makeRectangleSheet(0.04, 0.04, 0.01);
  mesh::placePattern(m, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY());
  for (Vec3& x : m.positions) x = Vec3(1.01 * x.x(), x.y(), 0.002 * std::sin(40.0 * x.y()));
  ElasticSheet sheet(m, officePaper(), SimParams{});
  const int inner = mesh::nearestPatternVertex(m, Vec2(0.02, 0.02));
  const int right = mesh::nearestPatternVertex(m, Vec2(0.04, 0.02));
  for (const int v : {inner, right}) {
    const auto forces = sheet.membraneForcesOn(v);
    EXPECT_GE(forces.size(), 2u);
    Vec3 total = Vec3::Zero();
    for (const auto& f : forces) total += f.force;
    Vec3 numeric;
    for (int c = 0; c < 3; ++c) {
      const double h = 1e-7;
      std::vector<Vec3> x = m.positions;
      x[static_cast<std::size_t>(v)][c] += h;
      sheet.setPositions(x);
      const double plus = sheet.membraneEnergy();
      x[static_cast<std::size_t>(v)][c] -= 2.0 * h;
      sheet.setPositions(x);
      numeric[c] = -(plus - sheet.membraneEnergy()) / (2.0 * h);
    }
    sheet.setPositions(m.positions);
    EXPECT_LT((total - numeric).norm(), 1e-6 * numeric.norm() + 1e-9) << "vertex " << v;
  }
  Vec3 pull = Vec3::Zero();
  for (const auto& f : sheet.membraneForcesOn(right)) pull += f.force;
  EXPECT_LT(pull.x(), 0.0) << "the stretched sheet pulls its right edge back";
  EXPECT_THROW(sheet.membraneForcesOn(-1), std::out_of_range);
}

// Checkpoint and resume: a sheet rebuilt on the same mesh and
// given the saved state goes on bit for bit as the one that never stopped;
// a state for another mesh is refused.
TEST(ElasticSheet, ASavedStateGoesOnBitForBit) {
  const mesh::SheetMesh m = a4Sheet(0.3);
  const PinFunction pins = topCorners(m);
  ElasticSheet whole(m, officePaper(), SimParams{});
  for (int step = 0; step < 12; ++step) whole.advance(step / 96.0, 1.0 / 96.0, pins);
  whole.setHingeRestAngle(3, 0.25);  // state a tear or the crumpling model would set
  whole.setHingeStiffnessFactor(5, 0.5);
  StateWriter w;
  whole.saveState(w);
  ElasticSheet resumed(m, officePaper(), SimParams{});
  StateReader r(w.data(), "test state");
  resumed.restoreState(r);
  EXPECT_TRUE(r.atEnd());
  for (int step = 12; step < 24; ++step) {
    whole.advance(step / 96.0, 1.0 / 96.0, pins);
    resumed.advance(step / 96.0, 1.0 / 96.0, pins);
  }
  EXPECT_TRUE(bitIdentical(whole.positions(), resumed.positions()));
  EXPECT_TRUE(bitIdentical(whole.velocities(), resumed.velocities()));
  EXPECT_EQ(resumed.hingeRestAngle(3), 0.25);
  ElasticSheet other(a4Sheet(0.3, 0.03), officePaper(), SimParams{});
  StateReader again(w.data(), "test state");
  EXPECT_THROW(other.restoreState(again), CorruptDataError);
}
