// Shape-Up projection with hard constraints (paper Sec. 7.2, Table III):
// an isometric input is a fixed point, a noisy rolled sheet is pulled back to
// its pattern lengths, handles never move, failures throw without touching
// the input, and the output is deterministic.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "crumple/core/error.hpp"
#include "crumple/core/rng.hpp"
#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/paper/hybrid_sheet.hpp"
#include "crumple/paper/initial_sheet.hpp"
#include "crumple/paper/shape_up.hpp"

using namespace crumple;
using namespace crumple::paper;

namespace {

// A 10 x 6 cm criss-cross sheet (180 triangles at 12 mm) and the vertices at
// its pattern corners (0, 0) and (0.10, 0): the handles.
struct Sheet {
  mesh::SheetMesh mesh = mesh::makeRectangleSheet(0.10, 0.06, 0.012);
  std::vector<int> handles() const {
    std::vector<int> out;
    for (const Vec2& corner : {Vec2(0.0, 0.0), Vec2(0.10, 0.0)}) {
      int best = 0;
      for (std::size_t v = 0; v < mesh.pattern.size(); ++v)
        if ((mesh.pattern[v] - corner).norm() < (mesh.pattern[best] - corner).norm())
          best = static_cast<int>(v);
      out.push_back(best);
    }
    return out;
  }
};

// A pattern point on the 3 cm cylinder about the y axis (arc length kept).
Vec3 onCylinder(const Vec2& q) {
  constexpr double kRadius = 0.03;
  const double angle = q.x() / kRadius;
  return {kRadius * std::sin(angle), q.y(), kRadius * (1.0 - std::cos(angle))};
}

// The sheet rolled onto the cylinder, every coordinate but the handles'
// moved by seeded uniform noise of 1 % of the 12 mm edge.
std::vector<Vec3> noisyRoll(const Sheet& s, std::uint64_t seed) {
  std::vector<Vec3> p(s.mesh.pattern.size());
  std::transform(s.mesh.pattern.begin(), s.mesh.pattern.end(), p.begin(), onCylinder);
  const std::vector<int> handles = s.handles();
  const CounterRng rng(seed, 0, RngPurpose::Generic);
  for (std::size_t v = 0; v < p.size(); ++v) {
    if (std::find(handles.begin(), handles.end(), static_cast<int>(v)) != handles.end()) continue;
    const Vec3 u(rng.uniform(3 * v), rng.uniform(3 * v + 1), rng.uniform(3 * v + 2));
    p[v] += 1.2e-4 * (2.0 * u - Vec3::Ones());
  }
  return p;
}

bool bitwiseEqual(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3)) == 0;
}

}  // namespace

// A flat sheet moved rigidly into 3D is already isometric: zero iterations,
// nothing moves, with handles and without (the floating-component path).
TEST(ShapeUp, IsometricInputIsAFixedPoint) {
  const Sheet s;
  const Mat3 rot = Quat(0.3, 0.9, -0.2, 0.4).normalized().toRotationMatrix();
  std::vector<Vec3> rigid;
  for (const Vec2& q : s.mesh.pattern) rigid.push_back(rot * Vec3(q.x(), q.y(), 0.0));
  for (const std::vector<int>& fixed : {s.handles(), std::vector<int>{}}) {
    const ShapeUpProjector projector(s.mesh.pattern, s.mesh.triangles, fixed);
    std::vector<Vec3> p = rigid;
    const ShapeUpStats st = projector.project(p);
    EXPECT_TRUE(st.converged);
    EXPECT_EQ(st.iterations, 0);
    EXPECT_LT(st.meanDisplacement, 1e-15);
    EXPECT_LT(st.meanLengthErrorAfter, 1e-12);
  }
}

// The noisy roll: c_mean falls by a large factor, every triangle ends near
// its rigid projection, the handles stay exactly put, and the stats agree
// with the positions.
TEST(ShapeUp, NoisyRollIsRestored) {
  const Sheet s;
  const std::vector<int> fixed = s.handles();
  const std::vector<Vec3> noisy = noisyRoll(s, 7);
  const ShapeUpProjector projector(s.mesh.pattern, s.mesh.triangles, fixed);
  std::vector<Vec3> p = noisy;
  const ShapeUpStats st = projector.project(p);
  std::printf(
      "noisy roll: c_mean %.3e -> %.3e (max %.3e), %d iterations, residual %.3e, d_m %.3e\n",
      st.meanLengthErrorBefore, st.meanLengthErrorAfter, st.maxLengthErrorAfter, st.iterations,
      st.maxTriangleResidual, st.meanDisplacement);
  EXPECT_GT(st.meanLengthErrorBefore, 1e-3);
  EXPECT_LT(st.meanLengthErrorAfter, st.meanLengthErrorBefore / 20.0);
  EXPECT_GT(st.iterations, 0);
  EXPECT_LT(st.maxTriangleResidual, 1e-3);
  for (int h : fixed) EXPECT_EQ(p[h], noisy[h]) << "handle " << h << " moved";
  EXPECT_EQ(meanLengthError(s.mesh.pattern, s.mesh.triangles, noisy), st.meanLengthErrorBefore);
  EXPECT_EQ(meanLengthError(s.mesh.pattern, s.mesh.triangles, p), st.meanLengthErrorAfter);
  double disp = 0.0;
  for (std::size_t v = 0; v < p.size(); ++v) disp += (p[v] - noisy[v]).norm();
  EXPECT_NEAR(st.meanDisplacement, disp / static_cast<double>(p.size()), 1e-15);
  // More iterations never leave it worse; the cap is honoured.
  const ShapeUpProjector capped(s.mesh.pattern, s.mesh.triangles, fixed, {.maxIterations = 3});
  std::vector<Vec3> c = noisy;
  const ShapeUpStats sc = capped.project(c);
  EXPECT_EQ(sc.iterations, 3);
  EXPECT_FALSE(sc.converged);
  EXPECT_GE(sc.maxTriangleResidual, st.maxTriangleResidual);
  // Stopping at a c_mean target: fewer iterations, the target met.
  const double target = 4.0 * st.meanLengthErrorAfter;
  const ShapeUpProjector early(s.mesh.pattern, s.mesh.triangles, fixed,
                               {.meanLengthTolerance = target});
  std::vector<Vec3> e = noisy;
  const ShapeUpStats se = early.project(e);
  EXPECT_TRUE(se.converged);
  EXPECT_LE(se.meanLengthErrorAfter, target);
  EXPECT_GT(se.iterations, 0);
  EXPECT_LT(se.iterations, st.iterations);
  // With no iteration allowed nothing moves.
  const ShapeUpProjector none(s.mesh.pattern, s.mesh.triangles, fixed, {.maxIterations = 0});
  std::vector<Vec3> z = noisy;
  EXPECT_EQ(none.project(z).iterations, 0);
  EXPECT_TRUE(bitwiseEqual(z, noisy));
}

// Non-finite or inconsistent input throws NumericalError naming the stage
// and the vertex, leaving the positions untouched; bad topology or options
// are std::invalid_argument.
TEST(ShapeUp, BadInputThrowsAndLeavesPositions) {
  const Sheet s;
  const ShapeUpProjector projector(s.mesh.pattern, s.mesh.triangles, s.handles());
  for (const double bad :
       {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    std::vector<Vec3> p = noisyRoll(s, 3);
    p[5].z() = bad;
    const std::vector<Vec3> before = p;
    try {
      projector.project(p);
      ADD_FAILURE() << "no NumericalError for a non-finite position";
    } catch (const NumericalError& e) {
      EXPECT_EQ(e.stage(), "shape-up");
      EXPECT_NE(std::string(e.what()).find("vertex 5"), std::string::npos) << e.what();
    }
    EXPECT_TRUE(bitwiseEqual(p, before));
  }
  std::vector<Vec3> shortList = noisyRoll(s, 3);
  shortList.pop_back();
  EXPECT_THROW(projector.project(shortList), NumericalError);
  const std::vector<Vec2> tri{{0, 0}, {1, 0}, {0, 1}};
  EXPECT_THROW(ShapeUpProjector(tri, {{0, 1, 3}}, {}), std::invalid_argument);
  EXPECT_THROW(ShapeUpProjector(tri, {{0, 2, 2}}, {}), std::invalid_argument);
  EXPECT_THROW(ShapeUpProjector(tri, {{0, 1, 2}}, {3}), std::invalid_argument);
  EXPECT_THROW(ShapeUpProjector({{0, 0}, {0, 0}, {0, 1}}, {{0, 1, 2}}, {}), std::invalid_argument);
  EXPECT_THROW(ShapeUpProjector(tri, {{0, 1, 2}}, {}, {.tolerance = 0.0}), std::invalid_argument);
  EXPECT_THROW(ShapeUpProjector(tri, {{0, 1, 2}}, {}, {.maxIterations = -1}),
               std::invalid_argument);
  const ShapeUpProjector one(tri, {{0, 1, 2}}, {0});
  EXPECT_EQ(one.vertexCount(), 3);
  EXPECT_EQ(one.edgeCount(), 3);
}

// Two projectors on the same input give bit-identical output.
TEST(ShapeUp, Deterministic) {
  const Sheet s;
  const std::vector<Vec3> noisy = noisyRoll(s, 11);
  std::vector<Vec3> a = noisy, b = noisy;
  const ShapeUpStats sa =
      ShapeUpProjector(s.mesh.pattern, s.mesh.triangles, s.handles()).project(a);
  const ShapeUpStats sb =
      ShapeUpProjector(s.mesh.pattern, s.mesh.triangles, s.handles()).project(b);
  EXPECT_TRUE(bitwiseEqual(a, b));
  EXPECT_FALSE(bitwiseEqual(a, noisy));
  EXPECT_EQ(sa.iterations, sb.iterations);
  EXPECT_EQ(sa.meanLengthErrorAfter, sb.meanLengthErrorAfter);
}

// The comparison's inputs (paper Table III): HybridSheet hands its
// projection callback exactly what the isometry projection gets, once per
// animation step, and both projections run on it.
TEST(ShapeUp, HybridSheetHandsItsProjectionInputs) {
  constexpr double kL = 0.10;
  const std::vector<Vec2> corners{Vec2(0, 0), Vec2(kL, 0), Vec2(kL, kL), Vec2(0, kL)};
  const InitialSheet sheet =
      makeFlatSheet(kL, kL, corners, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY());
  sim::SimParams weightless;
  weightless.gravity = Vec3::Zero();
  HybridSheet hybrid(sheet.mesh, sim::Material{}, weightless, CrumpleParams{}, 3);
  // The edge x = L pushed 4 % towards x = 0 over the frames, lifted a little.
  const auto pins = [&](double t, std::vector<sim::Pin>& out) {
    out.clear();
    for (std::size_t k = 0; k < corners.size(); ++k) {
      const double push = corners[k].x() > 0.0 ? std::min(t, 0.2) * 0.2 * kL : 0.0;
      out.push_back(
          {sheet.handleVertices[k], Vec3(corners[k].x() - push, corners[k].y(), 0.1 * push)});
    }
  };
  struct Seen {
    int frame = 0;
    std::vector<Vec3> positions;
    std::vector<int> fixed;
    IsometryStats replayed;
    ShapeUpStats shapeUp;
  };
  std::vector<Seen> seen;
  hybrid.setProjectionCallback([&](const ProjectionInput& in) {
    Seen s{in.frame, in.positions, in.fixed, {}, {}};
    std::vector<Vec3> a = in.positions, b = in.positions;
    s.replayed = IsometryProjector(in.pattern, in.triangles, in.fixed, in.options)
                     .project(a, in.maxIterations);
    s.shapeUp = ShapeUpProjector(in.pattern, in.triangles, in.fixed).project(b);
    for (int v : in.fixed) EXPECT_EQ(b[v], in.positions[v]);
    seen.push_back(std::move(s));
  });
  for (int f = 0; f < 4; ++f) {
    const std::size_t before = seen.size();
    const HybridStepStats st = hybrid.advance(f / 24.0, 1.0 / 24.0, 2, pins, f + 1);
    ASSERT_EQ(seen.size(), before + 2) << "one call per animation step";
    const Seen& last = seen.back();
    EXPECT_EQ(last.frame, f + 1);
    EXPECT_EQ(last.fixed.size(), corners.size());
    // The frame's isometry stats are its last step's: the replay on the
    // handed input reproduces them.
    EXPECT_EQ(last.replayed.meanLengthErrorBefore, st.isometry.meanLengthErrorBefore);
    if (last.replayed.meanLengthErrorAfter <= last.replayed.meanLengthErrorBefore) {
      EXPECT_EQ(last.replayed.meanLengthErrorAfter, st.isometry.meanLengthErrorAfter);
    }
    EXPECT_EQ(last.shapeUp.meanLengthErrorBefore, st.isometry.meanLengthErrorBefore);
  }
  std::printf("last step: c_mean %.3e -> ours %.3e, Shape-Up %.3e (%d iterations)\n",
              seen.back().replayed.meanLengthErrorBefore, seen.back().replayed.meanLengthErrorAfter,
              seen.back().shapeUp.meanLengthErrorAfter, seen.back().shapeUp.iterations);
  EXPECT_GT(seen.back().replayed.meanLengthErrorBefore, 0.0);
  // Unset again: no more calls.
  hybrid.setProjectionCallback({});
  const std::size_t count = seen.size();
  hybrid.advance(4 / 24.0, 1.0 / 24.0, 2, pins, 5);
  EXPECT_EQ(seen.size(), count);
}
