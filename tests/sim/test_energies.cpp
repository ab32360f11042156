// Finite-difference checks of the per-element energies (paper Sec. 4:
// Green-strain membrane, discrete flexural energy) and the bending-constant
// calibration against the continuum plate energy.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <string>

#include "crumple/core/rng.hpp"
#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/sim/elastic_sheet.hpp"
#include "crumple/sim/energies.hpp"
#include "fd_check.hpp"

using namespace crumple;
using namespace crumple::sim;
using namespace crumple::testing;

namespace {

constexpr double kTolerance = 1e-5;

std::string sci(double v) {  // measured figures for the gtest XML report
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3e", v);
  return buf;
}

Material officePaper() { return Material{}; }  // the office-70gsm preset

// A random non-degenerate pattern triangle (edges ~ 2 cm) and a strained,
// rotated 3D placement of it.
struct TriangleCase {
  TriangleRest rest;
  Vec9 x;
};
TriangleCase randomTriangle(std::uint64_t seed, double strain) {
  Random r(seed);
  Vec2 p[3];
  for (;;) {
    for (auto& q : p) q = Vec2(r.uniform(0, 0.02), r.uniform(0, 0.02));
    const double area =
        0.5 * ((p[1] - p[0]).x() * (p[2] - p[0]).y() - (p[1] - p[0]).y() * (p[2] - p[0]).x());
    if (area > 4e-5) break;  // well shaped
    if (area < -4e-5) {
      std::swap(p[1], p[2]);
      break;
    }
  }
  TriangleCase c;
  c.rest = triangleRest(p[0], p[1], p[2]);
  const Mat3 rot = r.rotation();
  const Vec3 shift = r.vec3(0.1);
  for (int a = 0; a < 3; ++a) {
    const Vec3 flat(p[a].x(), p[a].y(), 0.0);
    c.x.segment<3>(3 * a) = rot * flat + shift + r.vec3(strain * 0.02);
  }
  return c;
}

// A hinge with fold angle ~phi: edge x0-x1, wings x2 (triangle A) and x3
// (triangle B), randomly shaped, rotated and perturbed.
Vec12 randomHinge(std::uint64_t seed, double phi, double noise) {
  Random r(seed);
  const double len = r.uniform(0.01, 0.03);
  const Vec3 x0(0, 0, 0), x1(len, 0, 0);
  // Triangle A = (x0, x1, x2) counter-clockwise about +z: x2 at y > 0.
  const Vec3 x2(r.uniform(-0.3, 1.3) * len, r.uniform(0.4, 1.2) * len, 0.0);
  // Triangle B = (x1, x0, x3): x3 at y < 0 in the flat state, then folded
  // about the edge (x axis) by phi.
  const Vec3 flat3(r.uniform(-0.3, 1.3) * len, -r.uniform(0.4, 1.2) * len, 0.0);
  const Vec3 x3 = Eigen::AngleAxisd(phi, Vec3::UnitX()) * flat3;
  const Mat3 rot = r.rotation();
  const Vec3 shift = r.vec3(0.1);
  Vec12 out;
  const Vec3 xs[4] = {x0, x1, x2, x3};
  for (int a = 0; a < 4; ++a) out.segment<3>(3 * a) = rot * xs[a] + shift + r.vec3(noise * len);
  return out;
}

}  // namespace

TEST(MembraneEnergy, ZeroAndStressFreeUnderRigidMotion) {
  const TriangleCase c = randomTriangle(1, 0.0);
  const MembraneModuli mod = membraneModuli(officePaper());
  Vec9 g;
  const double w =
      membraneEnergy(c.x.segment<3>(0), c.x.segment<3>(3), c.x.segment<3>(6), c.rest, mod, &g);
  EXPECT_LT(w, 1e-12);
  EXPECT_LT(g.norm(), 1e-4);
}

TEST(MembraneEnergy, UniaxialStretchMatchesPlaneStressStVK) {
  // Unit right triangle stretched by s along x: E = diag((s^2-1)/2, 0),
  // W = A h (lambda/2 + mu) E_xx^2 = A/2 * stretchStiffness * E_xx^2.
  const Material mat = officePaper();
  const TriangleRest rest = triangleRest(Vec2(0, 0), Vec2(1, 0), Vec2(0, 1));
  const double s = 1.01;
  const double exx = 0.5 * (s * s - 1.0);
  const double w =
      membraneEnergy(Vec3(0, 0, 0), Vec3(s, 0, 0), Vec3(0, 1, 0), rest, membraneModuli(mat));
  EXPECT_NEAR(w / (0.5 * 0.5 * mat.stretchStiffness() * exx * exx), 1.0, 1e-12);
  const Mat2 e = greenStrain(Vec3(0, 0, 0), Vec3(s, 0, 0), Vec3(0, 1, 0), rest);
  EXPECT_NEAR(maxAbsPrincipal(e), exx, 1e-15);
}

TEST(MembraneEnergy, GradientAndHessianMatchFiniteDifferences) {
  const MembraneModuli mod = membraneModuli(officePaper());
  double worstGradient = 0.0, worstHessian = 0.0;
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    // Stretched (strain ~ 10%) and compressed / inverted configurations.
    const double strain = seed % 2 == 0 ? 0.1 : 0.5;
    const TriangleCase c = randomTriangle(seed, strain);
    auto energy = [&](const Vec9& x) {
      return membraneEnergy(x.segment<3>(0), x.segment<3>(3), x.segment<3>(6), c.rest, mod);
    };
    auto gradient = [&](const Vec9& x) {
      Vec9 g;
      membraneEnergy(x.segment<3>(0), x.segment<3>(3), x.segment<3>(6), c.rest, mod, &g);
      return g;
    };
    Vec9 g;
    Mat9 h;
    membraneEnergy(c.x.segment<3>(0), c.x.segment<3>(3), c.x.segment<3>(6), c.rest, mod, &g, &h);
    const double eps = 1e-7;  // coordinates ~ 2 cm
    const Vec9 gfd = fdGradient<9>(energy, c.x, eps);
    const Mat9 hfd = fdHessian<9>(gradient, c.x, eps);
    worstGradient = std::max(worstGradient, relativeError(g, gfd, 1e-12));
    worstHessian = std::max(worstHessian, relativeError(h, hfd, 1e-12));
    EXPECT_LT(relativeError(g, gfd, 1e-12), kTolerance) << "seed " << seed;
    EXPECT_LT(relativeError(h, hfd, 1e-12), kTolerance) << "seed " << seed;
    EXPECT_LT((h - h.transpose()).norm(), 1e-12 * h.norm());
  }
  RecordProperty("worst_gradient_relative_error", sci(worstGradient));
  RecordProperty("worst_hessian_relative_error", sci(worstHessian));
}

TEST(GripEnergy, GradientAndHessianMatchFiniteDifferences) {
  Random r(11);
  for (int trial = 0; trial < 8; ++trial) {
    Vec9 x;
    for (int a = 0; a < 3; ++a) x.segment<3>(3 * a) = r.vec3(0.02);
    const double w0 = r.uniform(0.0, 1.0), w1 = r.uniform(0.0, 1.0 - w0);
    const Vec3 w(w0, w1, 1.0 - w0 - w1);
    const Vec3 target = r.vec3(0.02);
    const double k = r.uniform(10.0, 1e4);
    auto energy = [&](const Vec9& y) {
      return gripEnergy(y.segment<3>(0), y.segment<3>(3), y.segment<3>(6), w, target, k);
    };
    auto gradient = [&](const Vec9& y) {
      Vec9 g;
      gripEnergy(y.segment<3>(0), y.segment<3>(3), y.segment<3>(6), w, target, k, &g);
      return g;
    };
    Vec9 g;
    const double e =
        gripEnergy(x.segment<3>(0), x.segment<3>(3), x.segment<3>(6), w, target, k, &g);
    const Vec3 point = w(0) * x.segment<3>(0) + w(1) * x.segment<3>(3) + w(2) * x.segment<3>(6);
    EXPECT_NEAR(e, 0.5 * k * (point - target).squaredNorm(), 1e-12 * std::max(1.0, e));
    const double eps = 1e-7;
    EXPECT_LT(relativeError(g, fdGradient<9>(energy, x, eps), 1e-12), kTolerance) << trial;
    // The Hessian ElasticSheet assembles: k (w w^T) (x) I_3.
    Mat9 h = Mat9::Zero();
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) h.block<3, 3>(3 * a, 3 * b) = k * w(a) * w(b) * Mat3::Identity();
    EXPECT_LT(relativeError(h, fdHessian<9>(gradient, x, eps), 1e-12), kTolerance) << trial;
  }
}

TEST(DihedralAngle, SignConventionAndRange) {
  // A = (x0, x1, x2) counter-clockwise about +z. Lifting x3 towards +z
  // (the normal side) makes a valley seen from the normals: theta < 0.
  const Vec3 x0(0, 0, 0), x1(1, 0, 0), x2(0.5, 1, 0);
  EXPECT_DOUBLE_EQ(dihedralAngle(x0, x1, x2, Vec3(0.5, -1, 0)), 0.0);
  for (const double phi : {0.3, 1.0, 2.0, 3.0}) {
    const Vec3 x3 = Eigen::AngleAxisd(phi, Vec3::UnitX()) * Vec3(0.5, -1, 0);
    // Rotating by +phi about x lifts x3 to z < 0 (away from the normal).
    EXPECT_LT(x3.z(), 0.0);
    EXPECT_NEAR(dihedralAngle(x0, x1, x2, x3), phi, 1e-12);
    const Vec3 x3m = Eigen::AngleAxisd(-phi, Vec3::UnitX()) * Vec3(0.5, -1, 0);
    EXPECT_NEAR(dihedralAngle(x0, x1, x2, x3m), -phi, 1e-12);
  }
}

TEST(BendingEnergy, GradientAndHessianMatchFiniteDifferences) {
  const double d = officePaper().bendingStiffness();
  struct Case {
    double phi, rest;
  };
  const Case cases[] = {{0.0, 0.0}, {0.3, 0.0},  {-0.7, 0.2}, {1.2, -0.5},
                        {2.0, 0.3}, {-2.0, 0.0}, {2.1, 2.0},  {-2.2, -1.0}};
  std::uint64_t seed = 100;
  double worstGradient = 0.0, worstHessian = 0.0;
  for (const Case& c : cases) {
    for (int rep = 0; rep < 3; ++rep, ++seed) {
      const Vec12 x = randomHinge(seed, c.phi, 0.05);
      const double k = hingeStiffness(d, 1.0 + 0.5 * rep, 4e-4, 1.5e-4, 2.5e-4);
      auto energy = [&](const Vec12& y) {
        return bendingEnergy(y.segment<3>(0), y.segment<3>(3), y.segment<3>(6), y.segment<3>(9), k,
                             c.rest);
      };
      auto gradient = [&](const Vec12& y) {
        Vec12 g;
        bendingEnergy(y.segment<3>(0), y.segment<3>(3), y.segment<3>(6), y.segment<3>(9), k, c.rest,
                      &g);
        return g;
      };
      Vec12 g;
      Mat12 h;
      bendingEnergy(x.segment<3>(0), x.segment<3>(3), x.segment<3>(6), x.segment<3>(9), k, c.rest,
                    &g, &h);
      const double eps = 1e-7;  // coordinates ~ 2 cm
      const Vec12 gfd = fdGradient<12>(energy, x, eps);
      const Mat12 hfd = fdHessian<12>(gradient, x, eps);
      // Floors: the flat, rest-angle-0 case has a zero gradient.
      worstGradient = std::max(worstGradient, relativeError(g, gfd, 1e-10));
      worstHessian = std::max(worstHessian, relativeError(h, hfd, 1e-10));
      EXPECT_LT(relativeError(g, gfd, 1e-10), kTolerance) << "phi " << c.phi << " seed " << seed;
      EXPECT_LT(relativeError(h, hfd, 1e-10), kTolerance) << "phi " << c.phi << " seed " << seed;

      // The dihedral angle itself.
      auto angle = [](const Vec12& y) {
        return dihedralAngle(y.segment<3>(0), y.segment<3>(3), y.segment<3>(6), y.segment<3>(9));
      };
      auto angleGradient = [](const Vec12& y) {
        Vec12 ga;
        dihedralAngle(y.segment<3>(0), y.segment<3>(3), y.segment<3>(6), y.segment<3>(9), &ga);
        return ga;
      };
      Vec12 ga;
      Mat12 ha;
      const double theta = dihedralAngle(x.segment<3>(0), x.segment<3>(3), x.segment<3>(6),
                                         x.segment<3>(9), &ga, &ha);
      EXPECT_NEAR(theta, c.phi, 0.5);
      EXPECT_LT(relativeError(ga, fdGradient<12>(angle, x, eps), 1e-12), kTolerance);
      EXPECT_LT(relativeError(ha, fdHessian<12>(angleGradient, x, eps), 1e-12), kTolerance);
      // Translation invariance: the gradient sums to zero per axis.
      EXPECT_LT((ga.segment<3>(0) + ga.segment<3>(3) + ga.segment<3>(6) + ga.segment<3>(9)).norm(),
                1e-9 * ga.norm());
    }
  }
  RecordProperty("worst_gradient_relative_error", sci(worstGradient));
  RecordProperty("worst_hessian_relative_error", sci(worstHessian));
}

TEST(ProjectToPsd, ClampsNegativeEigenvalues) {
  Mat9 m = Mat9::Zero();
  m.diagonal() << 3, 2, 1, 0, -1, -2, 5, 6, -7;
  const Mat3 r = Random(7).rotation();
  Mat9 rot = Mat9::Zero();
  for (int a = 0; a < 3; ++a) rot.block<3, 3>(3 * a, 3 * a) = r;
  m = rot * m * rot.transpose();
  EXPECT_TRUE(projectToPsd(m));
  const Eigen::SelfAdjointEigenSolver<Mat9> eig(m);
  EXPECT_GT(eig.eigenvalues().minCoeff(), -1e-12);
  EXPECT_NEAR(eig.eigenvalues().maxCoeff(), 6.0, 1e-12);
  Mat9 psd = Mat9::Identity();
  EXPECT_FALSE(projectToPsd(psd));
}

// The reduced projection of a translation-invariant Hessian equals the full
// one: the true membrane and bending Hessians of a compressed triangle and of
// a hinge bent against its rest angle (both indefinite).
TEST(ProjectToPsd, TranslationInvariantReductionMatchesTheFullProjection) {
  const MembraneModuli moduli{1e6, 5e5, 1e-4};
  const TriangleRest rest = triangleRest(Vec2(0, 0), Vec2(0.01, 0), Vec2(0.003, 0.008));
  Mat9 tri;
  membraneEnergy(Vec3(0, 0, 0), Vec3(0.0093, 0.001, 0.0005), Vec3(0.002, 0.0071, -0.001), rest,
                 moduli, nullptr, &tri);
  Mat12 hinge;
  bendingEnergy(Vec3(0, 0, 0), Vec3(0.01, 0, 0), Vec3(0.004, 0.008, 0.002),
                Vec3(0.005, -0.007, 0.003), 2e-4, -0.9, nullptr, &hinge);
  Mat9 triFull = tri, triReduced = tri;
  Mat12 hingeFull = hinge, hingeReduced = hinge;
  ASSERT_TRUE(projectToPsd(triFull));  // both are indefinite
  ASSERT_TRUE(projectToPsd(hingeFull));
  EXPECT_TRUE(projectTranslationInvariantToPsd(triReduced));
  EXPECT_TRUE(projectTranslationInvariantToPsd(hingeReduced));
  EXPECT_LT((triReduced - triFull).norm(), 1e-12 * triFull.norm());
  EXPECT_LT((hingeReduced - hingeFull).norm(), 1e-12 * hingeFull.norm());
  // Translations stay in the kernel.
  Vec12 shift;
  for (int a = 0; a < 4; ++a) shift.segment<3>(3 * a) = Vec3(0.3, -0.2, 0.9);
  EXPECT_LT((hingeReduced * shift).norm(), 1e-12 * hingeReduced.norm());
  // A PSD Hessian (a stretched triangle) is left alone.
  Mat9 stretched;
  membraneEnergy(Vec3(0, 0, 0), Vec3(0.0102, 0, 0), Vec3(0.003, 0.0081, 0), rest, moduli, nullptr,
                 &stretched);
  Mat9 copy = stretched;
  EXPECT_FALSE(projectTranslationInvariantToPsd(copy));
  EXPECT_EQ(copy, stretched);
}

// Calibration of k_b = D/6 (energies.hpp): a sheet wrapped on a cylinder of
// radius R has the continuum energy D/2 kappa^2 * area.
namespace {

// An equilateral triangle lattice (n x n rows), counter-clockwise triangles.
mesh::SheetMesh equilateralLattice(int n, double a) {
  mesh::SheetMesh m;
  const double rowHeight = a * std::sqrt(3.0) / 2.0;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) m.pattern.emplace_back(a * i + (j % 2) * a / 2, rowHeight * j);
  auto id = [&](int i, int j) { return j * (n + 1) + i; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      if (j % 2 == 0) {
        m.triangles.push_back({id(i, j), id(i + 1, j), id(i, j + 1)});
        m.triangles.push_back({id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
      } else {
        m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
        m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
      }
    }
  m.positions.resize(m.pattern.size());
  m.regionOfTriangle.assign(m.triangles.size(), 0);
  m.regionTypes = {mesh::RegionType::Flat};
  return m;
}

// Discrete bending energy / continuum energy for the mesh wrapped about an
// axis at axisAngle from the pattern's v direction.
double cylinderRatio(mesh::SheetMesh m, double axisAngle, double radius) {
  const Material mat = officePaper();
  Vec2 centre = Vec2::Zero();
  for (const Vec2& p : m.pattern) centre += p;
  centre /= static_cast<double>(m.pattern.size());
  const Vec2 across(std::cos(axisAngle), -std::sin(axisAngle));
  const Vec2 along(std::sin(axisAngle), std::cos(axisAngle));
  for (std::size_t i = 0; i < m.vertexCount(); ++i) {
    const Vec2 p = m.pattern[i] - centre;
    const double s = p.dot(across), t = p.dot(along);
    const Vec2 inPlane = radius * std::sin(s / radius) * across + t * along;
    m.positions[i] = Vec3(inPlane.x(), inPlane.y(), radius * (1.0 - std::cos(s / radius)));
  }
  double area = 0.0;
  for (const auto& t : m.triangles)
    area += triangleRest(m.pattern[t[0]], m.pattern[t[1]], m.pattern[t[2]]).area;
  const ElasticSheet sheet(m, mat, SimParams{});
  return sheet.bendingEnergy() / (0.5 * mat.bendingStiffness() / (radius * radius) * area);
}

}  // namespace

TEST(BendingEnergy, CylinderMatchesContinuumPlateEnergyOnIsotropicMesh) {
  const mesh::SheetMesh lattice = equilateralLattice(60, 0.01);
  ASSERT_EQ(mesh::validate(lattice), "");
  for (const double angle : {0.0, 0.3, std::numbers::pi / 4, std::numbers::pi / 2}) {
    // Within 3.5%: the boundary hinges that do not exist cost ~1-2%.
    EXPECT_NEAR(cylinderRatio(lattice, angle, 0.4), 1.0, 0.035) << "axis angle " << angle;
    EXPECT_NEAR(cylinderRatio(lattice, angle, 0.1), 1.0, 0.035) << "axis angle " << angle;
  }
}

TEST(BendingEnergy, CrissCrossGridIsStifferAlongItsAxes) {
  // Documents the mesh dependence of discrete shells on makeRectangleSheet's
  // grid (energies.hpp): ~1.48x along a grid axis, ~1.0x along a diagonal.
  const mesh::SheetMesh grid = mesh::makeRectangleSheet(0.5, 0.5, 0.01);
  EXPECT_NEAR(cylinderRatio(grid, 0.0, 0.4), 1.48, 0.05);
  EXPECT_NEAR(cylinderRatio(grid, std::numbers::pi / 4, 0.4), 1.0, 0.05);
}
