// The air's terms (sim/air.hpp, docs/AIR.md): finite-difference checks of
// the implicit energy, the explicit forces against their definitions (the
// Munk moment as the derivative of the air's kinetic energy, lift
// perpendicular to the relative velocity), the wind field, the pieces'
// chords, sheltering, and a falling sheet reaching the terminal speed.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/sim/air.hpp"
#include "crumple/sim/elastic_sheet.hpp"
#include "fd_check.hpp"

using namespace crumple;
using namespace crumple::sim;
using crumple::testing::fdGradient;
using crumple::testing::fdHessian;
using crumple::testing::Random;
using crumple::testing::relativeError;

namespace {

Vec9 stack(const Vec3& a, const Vec3& b, const Vec3& c) {
  Vec9 x;
  x << a, b, c;
  return x;
}

AirTriangleFrame randomFrame(Random& r) {
  AirTriangleFrame f;
  f.normal = r.vec3(1.0).normalized();
  f.centroidStart = r.vec3(0.1);
  f.inertiaTarget = f.centroidStart + r.vec3(0.01);
  f.wind = r.vec3(2.0);
  f.drag = r.uniform(1e-4, 1e-2);
  f.addedMass = r.uniform(1e-5, 1e-3);
  return f;
}

}  // namespace

TEST(AirEnergy, GradientAndHessianMatchFiniteDifferences) {
  Random r(7);
  for (int trial = 0; trial < 20; ++trial) {
    const AirTriangleFrame f = randomFrame(r);
    const double h = r.uniform(1e-3, 2e-2);
    const Vec9 x = stack(f.centroidStart, f.centroidStart, f.centroidStart) +
                   stack(r.vec3(0.02), r.vec3(0.02), r.vec3(0.02));
    const auto energy = [&](const Vec9& y) {
      return airTriangleEnergy(f, h, y.segment<3>(0), y.segment<3>(3), y.segment<3>(6));
    };
    const auto gradient = [&](const Vec9& y) {
      Vec9 g;
      airTriangleEnergy(f, h, y.segment<3>(0), y.segment<3>(3), y.segment<3>(6), &g);
      return g;
    };
    Vec9 g;
    Mat9 hess;
    airTriangleEnergy(f, h, x.segment<3>(0), x.segment<3>(3), x.segment<3>(6), &g, &hess);
    EXPECT_LT(relativeError(g, fdGradient<9>(energy, x, 1e-7), 1e-9), 1e-6) << trial;
    EXPECT_LT(relativeError(hess, fdHessian<9>(gradient, x, 1e-7), 1e-6), 1e-5) << trial;
    // Convex: the Hessian is positive semi-definite.
    const Eigen::SelfAdjointEigenSolver<Mat9> eig(hess);
    EXPECT_GE(eig.eigenvalues().minCoeff(), -1e-9 * eig.eigenvalues().maxCoeff());
  }
}

TEST(AirEnergy, ItsForceIsTheDragAlongTheRelativeVelocity) {
  AirTriangleFrame f;
  f.drag = 0.003;
  f.wind = Vec3(1.0, 0.0, 0.0);
  const double h = 0.01;
  const Vec3 move(0.002, -0.01, 0.0);  // the centroid's displacement over the step
  Vec9 g;
  airTriangleEnergy(f, h, move, move, move, &g);
  const Vec3 u = move / h - f.wind;
  const Vec3 force = -(g.segment<3>(0) + g.segment<3>(3) + g.segment<3>(6));
  EXPECT_LT((force - (-f.drag * u.norm() * u)).norm(), 1e-12);
}

TEST(AirExplicit, TheMunkMomentIsTheDerivativeOfTheAirsKineticEnergy) {
  // Translation only (no turning): the explicit forces are dT/dx with
  // T = 1/2 m (u.n)^2 at fixed m (Lagrange's equations of the added mass).
  AirParams p;
  p.translationalLift = 0.0;
  p.rotationalLift = 0.0;
  Random r(11);
  for (int trial = 0; trial < 10; ++trial) {
    AirExplicitInput in;
    in.x = {r.vec3(0.05), r.vec3(0.05), r.vec3(0.05)};
    const Vec3 velocity = r.vec3(2.0);
    in.v = {velocity, velocity, velocity};
    in.wind = r.vec3(1.0);
    in.chord = 0.1;
    const auto forces = airExplicitForces(p, in);
    const double area = 0.5 * (in.x[1] - in.x[0]).cross(in.x[2] - in.x[0]).norm();
    const double m = p.density * p.addedMass * in.chord * area;
    const Vec3 u = velocity - in.wind;
    const auto kinetic = [&](const Vec9& y) {
      const Vec3 n =
          (y.segment<3>(3) - y.segment<3>(0)).cross(y.segment<3>(6) - y.segment<3>(0)).normalized();
      return 0.5 * m * std::pow(u.dot(n), 2.0);
    };
    const Vec9 fd = fdGradient<9>(kinetic, stack(in.x[0], in.x[1], in.x[2]), 1e-7);
    EXPECT_LT(relativeError(stack(forces[0], forces[1], forces[2]), fd, 1e-12), 1e-6) << trial;
    // No net force, a torque turning the face broadside to the flow.
    EXPECT_LT((forces[0] + forces[1] + forces[2]).norm(), 1e-12);
  }
}

// The circulation's lift given beside the forces is the forces without the
// added mass (openness 0), bit for bit: the corrector takes the lift so.
TEST(AirExplicit, TheCirculationAloneIsTheForcesWithoutTheAddedMass) {
  AirParams p;
  Random r(12);
  for (int trial = 0; trial < 10; ++trial) {
    AirExplicitInput in;
    in.x = {r.vec3(0.05), r.vec3(0.05), r.vec3(0.05)};
    in.v = {r.vec3(1.0), r.vec3(1.0), r.vec3(1.0)};
    in.wind = r.vec3(1.0);
    in.windRate = r.vec3(1.0);
    in.pieceVelocity = r.vec3(1.0);
    in.pieceSpin = r.vec3(5.0);
    in.chord = 0.1;
    in.openness = 0.7;
    std::array<Vec3, 3> circulation;
    const auto all = airExplicitForces(p, in, &circulation);
    in.openness = 0.0;
    const auto lift = airExplicitForces(p, in);
    for (std::size_t a = 0; a < 3; ++a) {
      EXPECT_EQ(circulation[a], lift[a]) << trial;
      EXPECT_GT((all[a] - lift[a]).norm(), 0.0) << trial;  // the added mass's part
    }
  }
}

TEST(AirExplicit, TranslationalLiftIsPerpendicularToTheRelativeVelocity) {
  AirParams p;
  p.rotationalLift = 0.0;
  p.addedMass = 0.0;
  AirExplicitInput in;
  in.x = {Vec3(0, 0, 0), Vec3(0.1, 0, 0), Vec3(0, 0.1, 0)};  // normal +z, area 0.005
  const double alpha = 0.3;                                  // angle of attack
  const Vec3 u = 2.0 * Vec3(std::cos(alpha), 0.0, -std::sin(alpha));
  in.v = {u, u, u};
  in.pieceVelocity = u;
  in.chord = 0.1;
  const auto f = airExplicitForces(p, in);
  const Vec3 lift = f[0] + f[1] + f[2];
  EXPECT_NEAR(lift.dot(u), 0.0, 1e-12);
  // Andersen et al.'s rho C_T |u|^2 sin(alpha) cos(alpha) per unit area.
  const double expected =
      p.density * p.translationalLift * 0.005 * u.squaredNorm() * std::sin(alpha) * std::cos(alpha);
  EXPECT_NEAR(lift.norm(), expected, 1e-12 * expected + 1e-15);
  // The face moves down into the air: the lift has an upward part.
  EXPECT_GT(lift.z(), 0.0);
}

TEST(AirExplicit, RotationalLiftIsHalfRhoCRChordOmegaCrossU) {
  AirParams p;
  p.translationalLift = 0.0;
  p.addedMass = 0.0;
  AirExplicitInput in;
  in.x = {Vec3(0, 0, 0), Vec3(0.1, 0, 0), Vec3(0, 0.1, 0)};
  const Vec3 c = (in.x[0] + in.x[1] + in.x[2]) / 3.0;
  const Vec3 omega(0.0, 3.0, 0.0);  // turning about an in-plane axis
  const Vec3 u(0.5, 0.0, -1.0);
  for (std::size_t a = 0; a < 3; ++a) in.v[a] = u + omega.cross(in.x[a] - c);
  in.pieceVelocity = u;
  in.pieceSpin = omega + Vec3(0.0, 0.0, 5.0);  // spin about the normal turns nothing
  in.chord = 0.08;
  const auto f = airExplicitForces(p, in);
  const Vec3 expected = 0.5 * p.density * p.rotationalLift * in.chord * 0.005 * omega.cross(u);
  EXPECT_LT((f[0] + f[1] + f[2] - expected).norm(), 1e-12 + 1e-9 * expected.norm());
}

TEST(WindField, KeysInterpolateAndGustsHaveTheirSpeed) {
  AirParams p;
  p.wind = {{1.0, Vec3(0, 0, 0)}, {2.0, Vec3(4, 0, 0)}};
  const WindField still(p);
  EXPECT_EQ(still.at(Vec3(1, 2, 3), 0.5), Vec3::Zero());
  EXPECT_LT((still.at(Vec3::Zero(), 1.25) - Vec3(1, 0, 0)).norm(), 1e-12);
  EXPECT_LT((still.at(Vec3::Zero(), 9.0) - Vec3(4, 0, 0)).norm(), 1e-12);
  EXPECT_LT((still.travel(2.0) - Vec3(2, 0, 0)).norm(), 1e-12);

  p.gusts.speed = 0.8;
  p.gusts.seed = 5;
  const WindField gusty(p);
  double sumSq = 0.0;
  int n = 0;
  double divergence = 0.0;
  Random r(3);
  for (int i = 0; i < 4000; ++i) {
    const Vec3 x = r.vec3(3.0);
    const double t = r.uniform(0.0, 20.0);
    sumSq += (gusty.at(x, t) - gusty.mean(t)).squaredNorm();
    ++n;
    if (i < 50) {
      double div = 0.0;
      for (int a = 0; a < 3; ++a) {
        Vec3 d = Vec3::Zero();
        d(a) = 1e-6;
        div += (gusty.at(x + d, t)(a) - gusty.at(x - d, t)(a)) / 2e-6;
      }
      divergence = std::max(divergence, std::abs(div));
    }
  }
  EXPECT_NEAR(std::sqrt(sumSq / n), 0.8, 0.08);
  EXPECT_LT(divergence, 1e-5);
  // Deterministic, and another seed is another field.
  EXPECT_EQ(WindField(p).at(Vec3(0.3, 0.1, 0.2), 1.7), gusty.at(Vec3(0.3, 0.1, 0.2), 1.7));
  p.gusts.seed = 6;
  EXPECT_NE(WindField(p).at(Vec3(0.3, 0.1, 0.2), 1.7), gusty.at(Vec3(0.3, 0.1, 0.2), 1.7));
}

// A step's wind, sampled at once for all points (WindField::sampleStep),
// is the field's at both ends of the step, across a key and with gusts.
TEST(WindField, AStepsSamplesAreTheFieldAtItsStartAndEnd) {
  AirParams p;
  p.wind = {{0.25, Vec3(0, 0, 0)}, {0.75, Vec3(3, 0.2, 0)}};
  p.gusts.speed = 0.6;
  p.gusts.seed = 2;
  Random r(9);
  std::vector<Vec3> points(40);
  for (Vec3& x : points) x = r.vec3(2.0);
  for (const bool gusts : {false, true}) {
    if (!gusts) p.gusts.speed = 0.0;
    if (gusts) p.gusts.speed = 0.6;
    const WindField field(p);
    for (const double t0 : {0.1, 0.7, 3.0}) {
      const double t1 = t0 + 0.01;
      std::vector<Vec3> start, end;
      field.sampleStep(points, t0, t1, start, end);
      ASSERT_EQ(start.size(), points.size());
      ASSERT_EQ(end.size(), points.size());
      for (std::size_t i = 0; i < points.size(); ++i) {
        EXPECT_LT((start[i] - field.at(points[i], t0)).norm(), 1e-12) << t0;
        EXPECT_LT((end[i] - field.at(points[i], t1)).norm(), 1e-12) << t0;
      }
    }
  }
}

TEST(AirModel, ChordsAreTwiceAreaOverPerimeterPerPiece) {
  mesh::SheetMesh strip = mesh::makeRectangleSheet(0.02, 0.1, 0.01);
  const AirModel air(AirParams{}, strip.triangles, strip.pattern, strip.vertexCount());
  EXPECT_NEAR(air.chord(0), 2.0 * 0.002 / 0.24, 1e-12);
}

TEST(AirModel, AFaceBehindAnotherLayerIsSheltered) {
  // Two squares 1 cm apart, the upper one turned over (a sheet folded onto
  // itself), both moving down through still air: the lower one meets the
  // air first, the upper one is behind it.
  mesh::SheetMesh a = mesh::makeRectangleSheet(0.1, 0.1, 0.05);
  mesh::SheetMesh both = a;
  const int offset = static_cast<int>(a.vertexCount());
  for (std::size_t i = 0; i < a.vertexCount(); ++i) {
    both.pattern.push_back(a.pattern[i] + Vec2(1.0, 0.0));
    both.positions.push_back(a.positions[i] + Vec3(0.0, 0.0, 0.01));
  }
  for (const auto& t : a.triangles)
    both.triangles.push_back({t[0] + offset, t[2] + offset, t[1] + offset});
  AirModel air(AirParams{}, both.triangles, both.pattern, both.vertexCount());
  const std::vector<Vec3> v(both.vertexCount(), Vec3(0.0, 0.0, -1.0));
  air.beginStep(both.positions, v, 0.0, 0.01);
  const std::size_t lower = 0, upper = a.triangles.size();
  EXPECT_DOUBLE_EQ(air.exposure()[lower], 1.0);
  EXPECT_NEAR(air.exposure()[upper], 0.01 / air.chord(upper), 1e-9);
  EXPECT_LT(air.frames()[upper].drag, 0.5 * air.frames()[lower].drag);
  // Each layer has one side open and one 1 cm from the other layer.
  EXPECT_NEAR(air.openness()[lower], 0.5 * (1.0 + 0.01 / air.chord(lower)), 1e-9);
  EXPECT_NEAR(air.openness()[upper], 0.5 * (1.0 + 0.01 / air.chord(upper)), 1e-9);
  // One square alone is not folded: it casts no rays, all of it is exposed.
  AirModel one(AirParams{}, a.triangles, a.pattern, a.vertexCount());
  one.beginStep(a.positions, std::vector<Vec3>(a.vertexCount(), Vec3(0.3, 0.0, -1.0)), 0.0, 0.01);
  for (std::size_t t = 0; t < a.triangles.size(); ++t) {
    EXPECT_EQ(one.exposure()[t], 1.0);
    EXPECT_EQ(one.openness()[t], 1.0);
  }
}

TEST(AirModel, TheCorrectorTakesTheForcesAtTheStepsMiddle) {
  // A 10 cm square tumbling about an in-plane axis while it drifts: the
  // lift frozen at the step's start lags its turning by half a step (an
  // error of order h); the corrected one, the mean of the start's and the
  // end's, is the middle's to order h^2. (No added mass: its forces stay
  // the start's.)
  mesh::SheetMesh m = mesh::makeRectangleSheet(0.1, 0.1, 0.05);
  mesh::placePattern(m, Vec3(-0.05, 0.0, 0.05), Vec3::UnitX(), -Vec3::UnitZ());
  const Vec3 omega(6.0, 0.0, 0.0), drift(0.8, 0.3, -0.5);
  const auto state = [&](double t, std::vector<Vec3>& x, std::vector<Vec3>& v) {
    const Mat3 turn = Eigen::AngleAxisd(omega.norm() * t, omega.normalized()).toRotationMatrix();
    x.resize(m.vertexCount());
    v.resize(m.vertexCount());
    for (std::size_t i = 0; i < x.size(); ++i) {
      x[i] = turn * m.positions[i] + t * drift;
      v[i] = omega.cross(turn * m.positions[i]) + drift;
    }
  };
  AirParams params;
  params.addedMass = 0.0;
  AirModel air(params, m.triangles, m.pattern, m.vertexCount());
  const double h = 0.01;
  std::vector<Vec3> x, v;
  state(0.5 * h, x, v);
  air.beginStep(x, v, 0.0, h);
  const std::vector<Vec3> middle = air.explicitForces();
  std::vector<double> middleDrag;
  for (const auto& f : air.frames()) middleDrag.push_back(f.drag);
  state(0.0, x, v);
  air.beginStep(x, v, 0.0, h);
  const std::vector<Vec3> start = air.explicitForces();
  std::vector<double> startDrag;
  for (const auto& f : air.frames()) startDrag.push_back(f.drag);
  state(h, x, v);
  const std::vector<Vec3> change = air.correctStep(x, v);
  double lagStart = 0.0, lagCorrected = 0.0, scale = 0.0;
  for (std::size_t i = 0; i < middle.size(); ++i) {
    lagStart = std::max(lagStart, (start[i] - middle[i]).norm());
    lagCorrected = std::max(lagCorrected, (air.explicitForces()[i] - middle[i]).norm());
    scale = std::max(scale, middle[i].norm());
    EXPECT_TRUE(change[i].allFinite());
  }
  EXPECT_GT(lagStart, 1e-3 * scale) << "the test turns the square enough to see the lag";
  EXPECT_LT(lagCorrected, 0.05 * lagStart);
  double dragStart = 0.0, dragCorrected = 0.0;
  for (std::size_t t = 0; t < middleDrag.size(); ++t) {
    dragStart = std::max(dragStart, std::abs(startDrag[t] - middleDrag[t]));
    dragCorrected = std::max(dragCorrected, std::abs(air.frames()[t].drag - middleDrag[t]));
  }
  EXPECT_GT(dragStart, 0.0);
  EXPECT_LT(dragCorrected, 0.05 * dragStart);
}

TEST(AirModel, APiecesSpinAndVelocityAreItsRigidMotions) {
  // A sheet moving rigidly (v = V + omega x (x - c), c its centre): the
  // circulation the model gives every face is airExplicitForces' with the
  // piece's velocity V and spin omega, whatever the frame's origin.
  mesh::SheetMesh m = mesh::makeRectangleSheet(0.12, 0.08, 0.02);
  mesh::placePattern(m, Vec3(0.7, -0.3, 1.1), Vec3(0.6, 0.8, 0.0), Vec3(0.0, 0.0, 1.0));
  const Mat3 bend = Eigen::AngleAxisd(0.4, Vec3(0.3, -0.5, 0.8).normalized()).toRotationMatrix();
  Vec3 centre = Vec3::Zero();
  double total = 0.0;
  for (const auto& t : m.triangles) {
    // Lumped on the vertices as the sheet lumps its mass: a regular grid's
    // centre is its vertices' area-weighted mean, its centroid.
    const Vec3 c =
        (m.positions[static_cast<std::size_t>(t[0])] + m.positions[static_cast<std::size_t>(t[1])] +
         m.positions[static_cast<std::size_t>(t[2])]) /
        3.0;
    centre += c;
    total += 1.0;
  }
  centre /= total;
  const Vec3 omega(2.0, -7.0, 3.0), drift(0.4, 0.9, -1.3);
  std::vector<Vec3> x(m.vertexCount()), v(m.vertexCount());
  for (std::size_t i = 0; i < x.size(); ++i) {
    x[i] = centre + bend * (m.positions[i] - centre);
    v[i] = drift + omega.cross(x[i] - centre);
  }
  AirParams params;
  params.addedMass = 0.0;  // the circulation alone
  AirModel air(params, m.triangles, m.pattern, m.vertexCount());
  air.beginStep(x, v, 0.0, 0.01);
  std::vector<Vec3> expected(x.size(), Vec3::Zero());
  for (std::size_t t = 0; t < m.triangles.size(); ++t) {
    AirExplicitInput in;
    for (std::size_t a = 0; a < 3; ++a) {
      in.x[a] = x[static_cast<std::size_t>(m.triangles[t][a])];
      in.v[a] = v[static_cast<std::size_t>(m.triangles[t][a])];
    }
    in.pieceVelocity = drift;
    in.pieceSpin = omega;
    in.chord = air.chord(t);
    in.openness = 0.0;
    const auto f = airExplicitForces(params, in);
    for (std::size_t a = 0; a < 3; ++a)
      expected[static_cast<std::size_t>(m.triangles[t][a])] += f[a];
  }
  double scale = 0.0, error = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    scale = std::max(scale, expected[i].norm());
    error = std::max(error, (air.explicitForces()[i] - expected[i]).norm());
  }
  EXPECT_GT(scale, 0.0);
  EXPECT_LT(error, 1e-9 * scale);
}

TEST(AirSheet, AFlatSheetFallsAtTheQuasiSteadyTerminalSpeed) {
  // A 10 cm square of 70 g/m^2 falling level: sqrt(2 m g / (rho C_D A)).
  mesh::SheetMesh m = mesh::makeRectangleSheet(0.1, 0.1, 0.02);
  mesh::placePattern(m, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ());
  SimParams params;
  params.massDamping = 0.0;
  params.air.emplace();
  const Material paper;
  ElasticSheet sheet(m, paper, params);
  const double dt = 1.0 / 96.0;
  for (int step = 0; step < 96; ++step) sheet.advance(step * dt, dt, {});
  double vy = 0.0;
  for (const Vec3& v : sheet.velocities()) vy += v.y();
  vy /= static_cast<double>(sheet.velocities().size());
  const double terminal =
      std::sqrt(2.0 * paper.arealDensity() * 9.81 / (params.air->density * params.air->dragNormal));
  EXPECT_NEAR(-vy, terminal, 0.02 * terminal);
}

TEST(AirSheet, TheAddedMassCreatesNoEnergy) {
  // A 10 cm square spinning about an in-plane axis and drifting, without
  // gravity, in air with added mass only (no drag, no lift): the sheet's
  // kinetic and elastic energy and the air's kinetic energy
  // (1/2 m_a (u.n)^2 per face) must not grow: backward Euler only takes
  // energy away. (The wrong sign on the turning normal's terms makes it grow
  // by about 0.1 % a step.)
  mesh::SheetMesh m = mesh::makeRectangleSheet(0.1, 0.1, 0.02);
  mesh::placePattern(m, Vec3(-0.05, 0.0, 0.05), Vec3::UnitX(), -Vec3::UnitZ());
  SimParams params;
  params.gravity = Vec3::Zero();
  params.massDamping = 0.0;
  AirParams air;
  air.dragNormal = air.dragTangential = 0.0;
  air.translationalLift = air.rotationalLift = 0.0;
  params.air = air;
  ElasticSheet sheet(m, Material{}, params);
  std::vector<Vec3> v(m.vertexCount());
  const Vec3 omega(4.0, 0.0, 0.0);  // about x: the sheet tumbles
  for (std::size_t i = 0; i < v.size(); ++i)
    v[i] = omega.cross(m.positions[i]) + Vec3(0.3, 0.0, 0.0);
  sheet.setVelocities(v);
  AirModel model(air, m.triangles, m.pattern, m.vertexCount());
  const auto energy = [&] {
    model.beginStep(sheet.positions(), sheet.velocities(), 0.0, 1.0);
    double e = sheet.kineticEnergy() + sheet.membraneEnergy() + sheet.bendingEnergy();
    for (std::size_t t = 0; t < m.triangles.size(); ++t) {
      const auto& tri = m.triangles[t];
      Vec3 vbar = Vec3::Zero();
      for (int a : tri) vbar += sheet.velocities()[static_cast<std::size_t>(a)] / 3.0;
      const auto& f = model.frames()[t];
      e += 0.5 * f.addedMass * std::pow(vbar.dot(f.normal), 2.0);
    }
    return e;
  };
  const double e0 = energy();
  double last = e0;
  const double dt = 1.0 / 96.0;
  for (int step = 0; step < 96; ++step) {
    sheet.advance(step * dt, dt, {});
    const double e = energy();
    // The forces frozen at the step's start lag it: the first step, from a
    // velocity set at once, may gain a trace.
    EXPECT_LE(e, (step == 0 ? 1.001 : 1.0 + 1e-9) * last) << "step " << step;
    last = e;
  }
  EXPECT_GT(last, 0.5 * e0) << "and it does not lose most of it in a second";
}
