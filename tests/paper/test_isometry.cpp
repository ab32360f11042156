// Isometry projection of S_P onto its pattern (paper Sec. 6.3, eqs. (3)-(7)):
// exact isometries stay put, perturbed developable sheets are pulled back to
// their pattern lengths, handles never move, failures throw without touching
// the input, and the result is deterministic and independent of factor reuse.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "crumple/core/error.hpp"
#include "crumple/core/rng.hpp"
#include "crumple/mesh/sheet_mesh.hpp"
#include "crumple/paper/isometry.hpp"

using namespace crumple;
using namespace crumple::paper;

namespace {

constexpr double kWidth = 0.10;  // the 10 cm validation sheet

std::string sci(double v) {  // measured figures for the gtest XML report
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3e", v);
  return buf;
}

// A kWidth x height criss-cross grid (mesh::makeRectangleSheet) with its
// column count, so corner indices are known: (0,0) is vertex 0, (W,0) is nx.
struct Grid {
  mesh::SheetMesh sheet;
  int nx = 0;
  int cornerA() const { return 0; }
  int cornerB() const { return nx; }
  double dx() const { return kWidth / nx; }
};

Grid makeGrid(double height, double maxEdge) {
  Grid g;
  g.sheet = mesh::makeRectangleSheet(kWidth, height, maxEdge);
  g.nx = static_cast<int>(std::ceil(kWidth / maxEdge - 1e-9));
  return g;
}

// Mean over undirected edges of |l - lbar| / lbar, computed independently of
// the projector (each interior edge is seen twice, boundary edges once, so we
// deduplicate through mesh::buildEdges).
double meanLengthError(const mesh::SheetMesh& sheet, const std::vector<Vec3>& p) {
  const auto edges = mesh::buildEdges(sheet);
  double sum = 0.0;
  for (const auto& e : edges) {
    const double rest = (sheet.pattern[e.v[1]] - sheet.pattern[e.v[0]]).norm();
    sum += std::abs((p[e.v[1]] - p[e.v[0]]).norm() - rest) / rest;
  }
  return sum / static_cast<double>(edges.size());
}

double meanDistance(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double sum = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) sum += (a[i] - b[i]).norm();
  return sum / static_cast<double>(a.size());
}

double maxDistance(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double m = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) m = std::max(m, (a[i] - b[i]).norm());
  return m;
}

bool bitwiseEqual(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3)) == 0;
}

bool allFinite(const std::vector<Vec3>& p) {
  return std::all_of(p.begin(), p.end(), [](const Vec3& v) { return v.allFinite(); });
}

Vec3 centroid(const std::vector<Vec3>& p, int begin, int end) {
  Vec3 c = Vec3::Zero();
  for (int i = begin; i < end; ++i) c += p[i];
  return c / static_cast<double>(end - begin);
}

// The flat pattern moved rigidly into 3D.
std::vector<Vec3> placeRigidly(const std::vector<Vec2>& pattern) {
  const Mat3 rot = Quat(0.8, -0.3, 0.4, 0.2).normalized().toRotationMatrix();
  const Vec3 shift(0.31, -0.12, 0.57);
  std::vector<Vec3> out;
  for (const Vec2& q : pattern) out.push_back(rot * Vec3(q.x(), q.y(), 0.0) + shift);
  return out;
}

// Every vertex mapped exactly onto a cylinder of the given radius (axis along
// y). Edges crossing x become chords, slightly shorter than in the pattern.
std::vector<Vec3> rollOntoCylinder(const std::vector<Vec2>& pattern, double radius) {
  std::vector<Vec3> out;
  for (const Vec2& q : pattern) {
    const double a = q.x() / radius;
    out.emplace_back(radius * std::sin(a), q.y(), radius * (1.0 - std::cos(a)));
  }
  return out;
}

// The grid folded only along its vertical lines x = i dx onto a polygon
// inscribed in a cylinder: every cell stays planar, so the mesh is exactly
// developable and isometric to its pattern.
std::vector<Vec3> polyhedralRoll(const std::vector<Vec2>& pattern, double dx, double radius) {
  const double turn = 2.0 * std::asin(dx / (2.0 * radius));
  auto corner = [&](int k) {
    return Vec3(radius * std::sin(k * turn), 0.0, radius * (1.0 - std::cos(k * turn)));
  };
  std::vector<Vec3> out;
  for (const Vec2& q : pattern) {
    const double s = q.x() / dx;
    const int i = static_cast<int>(std::floor(s + 1e-9));
    const double f = s - i;
    Vec3 v = (1.0 - f) * corner(i) + f * corner(i + 1);
    v.y() = q.y();
    out.push_back(v);
  }
  return out;
}

// Seeded uniform noise in [-amplitude, amplitude] on every coordinate.
void addNoise(std::vector<Vec3>& p, double amplitude, std::uint64_t seed) {
  const CounterRng rng(seed, 0, RngPurpose::Generic);
  std::uint64_t k = 0;
  for (Vec3& v : p) {
    for (int c = 0; c < 3; ++c) v[c] += amplitude * (2.0 * rng.uniform(k++) - 1.0);
  }
}

double meanPatternEdge(const mesh::SheetMesh& sheet) {
  const auto edges = mesh::buildEdges(sheet);
  double sum = 0.0;
  for (const auto& e : edges) sum += (sheet.pattern[e.v[1]] - sheet.pattern[e.v[0]]).norm();
  return sum / static_cast<double>(edges.size());
}

// The perturbed developable sheet of test 2: polyhedral roll of radius 3 cm,
// 1 % noise, handles at the corners (0,0) and (W,0) left on the clean shape.
struct NoisyRoll {
  Grid grid;
  std::vector<Vec3> clean, noisy;
  double noiseAmplitude = 0.0;
};

NoisyRoll makeNoisyRoll(double height, double maxEdge, std::uint64_t seed) {
  NoisyRoll r;
  r.grid = makeGrid(height, maxEdge);
  r.clean = polyhedralRoll(r.grid.sheet.pattern, r.grid.dx(), 0.03);
  r.noisy = r.clean;
  r.noiseAmplitude = 0.01 * meanPatternEdge(r.grid.sheet);
  addNoise(r.noisy, r.noiseAmplitude, seed);
  r.noisy[r.grid.cornerA()] = r.clean[r.grid.cornerA()];
  r.noisy[r.grid.cornerB()] = r.clean[r.grid.cornerB()];
  return r;
}

}  // namespace

// Test 1: a flat grid placed rigidly in 3D is already isometric; it must not
// move, with handles and without (the centroid-preserving path).
TEST(Isometry, RigidFlatGridStaysPut) {
  const Grid g = makeGrid(0.06, 0.012);
  const std::vector<Vec3> input = placeRigidly(g.sheet.pattern);
  for (const std::vector<int>& fixed :
       {std::vector<int>{g.cornerA(), g.cornerB()}, std::vector<int>{}}) {
    IsometryProjector projector(g.sheet.pattern, g.sheet.triangles, fixed);
    std::vector<Vec3> p = input;
    const IsometryStats s = projector.project(p);
    EXPECT_LT(s.meanLengthErrorBefore, 1e-12);
    EXPECT_LT(s.meanLengthErrorAfter, 1e-12);
    EXPECT_EQ(s.phaseOneIterations, 0);  // constraints already satisfied
    EXPECT_LT(maxDistance(p, input), 1e-9);
    EXPECT_LT(s.meanDisplacement, 1e-9);
  }
}

// Test 1, curved: the exactly developable polyhedral roll stays put; the
// smooth roll (chords shorter than the pattern) does not get worse and moves
// little compared with its edge length.
TEST(Isometry, RolledGridStaysPut) {
  const Grid g = makeGrid(0.06, 0.012);
  const std::vector<int> fixed{g.cornerA(), g.cornerB()};
  {
    const std::vector<Vec3> input = polyhedralRoll(g.sheet.pattern, g.dx(), 0.03);
    IsometryProjector projector(g.sheet.pattern, g.sheet.triangles, fixed);
    std::vector<Vec3> p = input;
    const IsometryStats s = projector.project(p);
    EXPECT_LT(s.meanLengthErrorBefore, 1e-12);
    EXPECT_LT(s.meanLengthErrorAfter, 1e-12);
    EXPECT_LT(maxDistance(p, input), 1e-9);
  }
  {
    const std::vector<Vec3> input = rollOntoCylinder(g.sheet.pattern, 0.05);
    IsometryProjector projector(g.sheet.pattern, g.sheet.triangles, fixed);
    std::vector<Vec3> p = input;
    const IsometryStats s = projector.project(p);
    std::printf("smooth roll R=5cm: c_mean %.3e -> %.3e, d_m %.3e m\n", s.meanLengthErrorBefore,
                s.meanLengthErrorAfter, s.meanDisplacement);
    ::testing::Test::RecordProperty("smooth_roll_cmean_before", sci(s.meanLengthErrorBefore));
    ::testing::Test::RecordProperty("smooth_roll_cmean_after", sci(s.meanLengthErrorAfter));
    ::testing::Test::RecordProperty("smooth_roll_mean_displacement", sci(s.meanDisplacement));
    EXPECT_GT(s.meanLengthErrorBefore, 1e-4);  // the chords really are short
    EXPECT_LE(s.meanLengthErrorAfter, s.meanLengthErrorBefore);
    EXPECT_LT(s.meanDisplacement, 0.02 * meanPatternEdge(g.sheet));
    EXPECT_TRUE(allFinite(p));
  }
}

// Test 2: a perturbed developable sheet is pulled back towards isometry.
TEST(Isometry, PerturbedRollIsRestored) {
  const NoisyRoll r = makeNoisyRoll(0.06, 0.012, 42);  // 180 triangles
  const std::vector<int> fixed{r.grid.cornerA(), r.grid.cornerB()};
  IsometryProjector projector(r.grid.sheet.pattern, r.grid.sheet.triangles, fixed);
  std::vector<Vec3> p = r.noisy;
  const IsometryStats s = projector.project(p);
  const double noise = meanDistance(r.noisy, r.clean);
  const double toClean = meanDistance(p, r.clean);
  std::printf(
      "noisy roll (%zu triangles): c_mean %.3e -> %.3e (max %.3e), %d Phase I iterations, "
      "d_m %.3e m, input noise %.3e m, distance to the clean sheet %.3e m\n",
      r.grid.sheet.triangles.size(), s.meanLengthErrorBefore, s.meanLengthErrorAfter,
      s.maxLengthErrorAfter, s.phaseOneIterations, s.meanDisplacement, noise, toClean);
  ::testing::Test::RecordProperty("triangles", static_cast<int>(r.grid.sheet.triangles.size()));
  ::testing::Test::RecordProperty("cmean_before", sci(s.meanLengthErrorBefore));
  ::testing::Test::RecordProperty("cmean_after", sci(s.meanLengthErrorAfter));
  ::testing::Test::RecordProperty("cmax_after", sci(s.maxLengthErrorAfter));
  ::testing::Test::RecordProperty("phase_one_iterations", s.phaseOneIterations);
  ::testing::Test::RecordProperty("mean_displacement", sci(s.meanDisplacement));
  ::testing::Test::RecordProperty("mean_noise", sci(noise));
  ::testing::Test::RecordProperty("mean_distance_to_clean", sci(toClean));

  EXPECT_TRUE(allFinite(p));
  // The statistics agree with an independent measurement.
  EXPECT_NEAR(s.meanLengthErrorBefore, meanLengthError(r.grid.sheet, r.noisy), 1e-15);
  EXPECT_NEAR(s.meanLengthErrorAfter, meanLengthError(r.grid.sheet, p), 1e-15);
  EXPECT_NEAR(s.meanDisplacement, meanDistance(p, r.noisy), 1e-15);
  EXPECT_LT(s.meanLengthErrorAfter, s.meanLengthErrorBefore / 5.0);
  for (int v : fixed) {
    EXPECT_EQ(p[v], r.noisy[v]) << "handle " << v << " moved";
  }
  // Shape stays close: the result is nearer the clean isometric sheet than
  // the input was, and the vertices move by no more than the noise itself
  // (undoing the length-changing part of the noise is the whole point).
  EXPECT_LT(toClean, 0.6 * noise);
  EXPECT_LT(s.meanDisplacement, noise);
}

// Phase I carries the improvement: Phase II alone (no Phase I iteration) and
// the paper's literal anchored objective both stop far short of the default.
TEST(Isometry, PhaseOneDoesTheWork) {
  const NoisyRoll r = makeNoisyRoll(0.06, 0.012, 42);
  const std::vector<int> fixed{r.grid.cornerA(), r.grid.cornerB()};
  IsometryProjector projector(r.grid.sheet.pattern, r.grid.sheet.triangles, fixed);
  IsometryProjector anchored(r.grid.sheet.pattern, r.grid.sheet.triangles, fixed,
                             {.objective = PhaseOneObjective::Anchored});
  IsometryProjector twoRounds(r.grid.sheet.pattern, r.grid.sheet.triangles, fixed, {.rounds = 2});
  std::vector<Vec3> pDefault = r.noisy, pPhaseTwo = r.noisy, pAnchored = r.noisy, pTwo = r.noisy;
  const IsometryStats sDefault = projector.project(pDefault);
  const IsometryStats sPhaseTwo = projector.project(pPhaseTwo, 0);
  const IsometryStats sAnchored = anchored.project(pAnchored);
  const IsometryStats sTwo = twoRounds.project(pTwo);
  std::printf(
      "c_mean %.3e -> default %.3e | Phase II only %.3e | anchored (paper's E) %.3e | "
      "2 rounds %.3e\n",
      sDefault.meanLengthErrorBefore, sDefault.meanLengthErrorAfter, sPhaseTwo.meanLengthErrorAfter,
      sAnchored.meanLengthErrorAfter, sTwo.meanLengthErrorAfter);
  ::testing::Test::RecordProperty("cmean_phase_two_only", sci(sPhaseTwo.meanLengthErrorAfter));
  ::testing::Test::RecordProperty("cmean_anchored", sci(sAnchored.meanLengthErrorAfter));
  ::testing::Test::RecordProperty("cmean_two_rounds", sci(sTwo.meanLengthErrorAfter));
  EXPECT_EQ(sPhaseTwo.phaseOneIterations, 0);
  EXPECT_LT(sDefault.meanLengthErrorAfter, 0.2 * sPhaseTwo.meanLengthErrorAfter);
  EXPECT_LT(sAnchored.meanLengthErrorAfter, sAnchored.meanLengthErrorBefore);
  EXPECT_TRUE(allFinite(pAnchored));
  EXPECT_LT(sTwo.meanLengthErrorAfter, sDefault.meanLengthErrorAfter);
  EXPECT_EQ(sTwo.phaseOneIterations, 2 * 200);
}

// Test 3: a flat sheet compressed by 2 % in x is restored, with no handle (its
// centroid kept) and with one handle (which does not move).
TEST(Isometry, UniformCompressionIsRestored) {
  const Grid g = makeGrid(0.06, 0.012);
  std::vector<Vec3> input;
  for (const Vec2& q : g.sheet.pattern) input.emplace_back(0.98 * q.x(), q.y(), 0.0);
  const int n = static_cast<int>(input.size());
  {
    IsometryProjector projector(g.sheet.pattern, g.sheet.triangles, {});
    std::vector<Vec3> p = input;
    const IsometryStats s = projector.project(p);
    std::printf("compressed, free: c_mean %.3e -> %.3e, %d iterations\n", s.meanLengthErrorBefore,
                s.meanLengthErrorAfter, s.phaseOneIterations);
    ::testing::Test::RecordProperty("free_cmean_before", sci(s.meanLengthErrorBefore));
    ::testing::Test::RecordProperty("free_cmean_after", sci(s.meanLengthErrorAfter));
    EXPECT_GT(s.meanLengthErrorBefore, 5e-3);
    EXPECT_LT(s.meanLengthErrorAfter, 1e-3);
    EXPECT_LT(meanLengthError(g.sheet, p), 1e-3);
    EXPECT_LT((centroid(p, 0, n) - centroid(input, 0, n)).norm(), 1e-12);
    EXPECT_TRUE(allFinite(p));
  }
  {
    const int handle = g.cornerA();
    IsometryProjector projector(g.sheet.pattern, g.sheet.triangles, {handle});
    std::vector<Vec3> p = input;
    const IsometryStats s = projector.project(p);
    EXPECT_LT(s.meanLengthErrorAfter, 1e-3);
    EXPECT_EQ(p[handle], input[handle]);
  }
}

// Disconnected components without a handle are each restored and each keeps
// its own centroid (the Laplacian is singular per component).
TEST(Isometry, DisconnectedComponentsWithoutHandles) {
  const Grid g = makeGrid(0.04, 0.01);
  const int n = static_cast<int>(g.sheet.pattern.size());
  std::vector<Vec2> pattern = g.sheet.pattern;
  std::vector<std::array<int, 3>> triangles = g.sheet.triangles;
  for (const Vec2& q : g.sheet.pattern) pattern.push_back(q + Vec2(0.2, 0.0));
  for (const auto& t : g.sheet.triangles) triangles.push_back({t[0] + n, t[1] + n, t[2] + n});
  pattern.emplace_back(0.5, 0.5);  // an isolated vertex in no triangle
  std::vector<Vec3> input;
  for (const Vec2& q : pattern) input.emplace_back(0.98 * q.x(), q.y(), 0.01 * q.x());
  IsometryProjector projector(pattern, triangles, {});
  std::vector<Vec3> p = input;
  const IsometryStats s = projector.project(p);
  EXPECT_LT(s.meanLengthErrorAfter, 1e-3);
  EXPECT_TRUE(allFinite(p));
  EXPECT_LT((centroid(p, 0, n) - centroid(input, 0, n)).norm(), 1e-12);
  EXPECT_LT((centroid(p, n, 2 * n) - centroid(input, n, 2 * n)).norm(), 1e-12);
  EXPECT_EQ(p.back(), input.back());
}

// Test 4: topology comparison and factor reuse.
TEST(Isometry, SameTopologyAndFactorReuse) {
  const Grid g = makeGrid(0.06, 0.012);
  const std::vector<int> fixed{g.cornerA(), g.cornerB()};
  IsometryProjector projector(g.sheet.pattern, g.sheet.triangles, fixed);
  EXPECT_TRUE(projector.sameTopology(g.sheet.triangles, fixed));
  EXPECT_TRUE(projector.sameTopology(g.sheet.triangles, {g.cornerB(), g.cornerA(), g.cornerA()}));
  EXPECT_FALSE(projector.sameTopology(g.sheet.triangles, {g.cornerA()}));
  EXPECT_FALSE(projector.sameTopology(g.sheet.triangles, {}));
  auto fewer = g.sheet.triangles;
  fewer.pop_back();
  EXPECT_FALSE(projector.sameTopology(fewer, fixed));
  auto flipped = g.sheet.triangles;
  std::swap(flipped[3][0], flipped[3][1]);
  EXPECT_FALSE(projector.sameTopology(flipped, fixed));

  // A projector reused on a second shape gives exactly what a fresh one gives.
  const NoisyRoll first = makeNoisyRoll(0.06, 0.012, 7);
  const NoisyRoll second = makeNoisyRoll(0.06, 0.012, 8);
  std::vector<Vec3> a = first.noisy, b = second.noisy, c = second.noisy;
  projector.project(a);
  const IsometryStats sb = projector.project(b);
  IsometryProjector fresh(g.sheet.pattern, g.sheet.triangles, fixed);
  const IsometryStats sc = fresh.project(c);
  EXPECT_TRUE(bitwiseEqual(b, c));
  EXPECT_FALSE(bitwiseEqual(a, b));
  EXPECT_EQ(sb.phaseOneIterations, sc.phaseOneIterations);
  EXPECT_EQ(sb.meanLengthErrorAfter, sc.meanLengthErrorAfter);
}

// Test 5: non-finite or inconsistent input throws NumericalError naming the
// stage and leaves the positions untouched.
TEST(Isometry, DegenerateInputThrowsAndLeavesPositions) {
  const NoisyRoll r = makeNoisyRoll(0.06, 0.012, 3);
  IsometryProjector projector(r.grid.sheet.pattern, r.grid.sheet.triangles,
                              {r.grid.cornerA(), r.grid.cornerB()});
  for (const double bad :
       {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    std::vector<Vec3> p = r.noisy;
    p[5].y() = bad;
    const std::vector<Vec3> before = p;
    try {
      projector.project(p);
      ADD_FAILURE() << "no NumericalError for a non-finite position";
    } catch (const NumericalError& e) {
      EXPECT_EQ(e.stage(), "isometry");
      EXPECT_NE(std::string(e.what()).find("vertex 5"), std::string::npos) << e.what();
    }
    EXPECT_TRUE(bitwiseEqual(p, before));
  }
  {
    // An edge collapsed to zero length has no direction u0.
    const auto& t = r.grid.sheet.triangles.front();
    std::vector<Vec3> p = r.noisy;
    p[t[1]] = p[t[0]];
    const std::vector<Vec3> before = p;
    EXPECT_THROW(projector.project(p), NumericalError);
    EXPECT_TRUE(bitwiseEqual(p, before));
  }
  {
    std::vector<Vec3> p(r.noisy.begin(), r.noisy.end() - 1);  // one position short
    EXPECT_THROW(projector.project(p), NumericalError);
  }
}

TEST(Isometry, InvalidTopologyIsRejected) {
  const std::vector<Vec2> pattern{{0, 0}, {1, 0}, {0, 1}};
  EXPECT_THROW(IsometryProjector(pattern, {{0, 1, 3}}, {}), std::invalid_argument);
  EXPECT_THROW(IsometryProjector(pattern, {{0, 1, 1}}, {}), std::invalid_argument);
  EXPECT_THROW(IsometryProjector(pattern, {{0, 1, 2}}, {4}), std::invalid_argument);
  EXPECT_THROW(IsometryProjector({{0, 0}, {0, 0}, {0, 1}}, {{0, 1, 2}}, {}), std::invalid_argument);
  EXPECT_THROW(IsometryProjector(pattern, {{0, 1, 2}}, {}, {.rounds = 0}), std::invalid_argument);
  IsometryProjector ok(pattern, {{0, 1, 2}}, {0});
  EXPECT_EQ(ok.vertexCount(), 3);
  EXPECT_EQ(ok.edgeCount(), 3);
}

// Deviation 7: Gauss-Seidel length sweeps after Phase II take the noisy roll
// much closer to isometry than Phase I + II alone, keep the handles exactly
// where they were, and stop early once every edge is within tolerance.
TEST(Isometry, LengthSweepsPolishWhatPhaseTwoLeaves) {
  const NoisyRoll r = makeNoisyRoll(0.06, 0.012, 42);
  const std::vector<int> fixed{r.grid.cornerA(), r.grid.cornerB()};
  IsometryProjector paper(r.grid.sheet.pattern, r.grid.sheet.triangles, fixed);
  std::vector<Vec3> a = r.noisy;
  const IsometryStats sa = paper.project(a);
  EXPECT_EQ(sa.lengthSweeps, 0);
  IsometryProjector polished(r.grid.sheet.pattern, r.grid.sheet.triangles, fixed,
                             {.lengthSweeps = 300, .lengthTolerance = 1e-6});
  std::vector<Vec3> b = r.noisy;
  const IsometryStats sb = polished.project(b);
  std::printf("noisy roll: c_mean %.3e (Phase I + II) -> %.3e (+ %d sweeps), max %.3e\n",
              sa.meanLengthErrorAfter, sb.meanLengthErrorAfter, sb.lengthSweeps,
              sb.maxLengthErrorAfter);
  ::testing::Test::RecordProperty("cmean_phase_one_two", sci(sa.meanLengthErrorAfter));
  ::testing::Test::RecordProperty("cmean_with_sweeps", sci(sb.meanLengthErrorAfter));
  ::testing::Test::RecordProperty("sweeps", sb.lengthSweeps);
  EXPECT_NEAR(sb.meanLengthErrorAfter, meanLengthError(r.grid.sheet, b), 1e-15);
  EXPECT_LT(sb.meanLengthErrorAfter, sa.meanLengthErrorAfter / 5.0);
  EXPECT_GT(sb.lengthSweeps, 0);
  if (sb.lengthSweeps < 300) {
    EXPECT_LT(sb.maxLengthErrorAfter, 1e-6);  // stopped at tolerance
  }
  for (int v : fixed) EXPECT_EQ(b[v], r.noisy[v]) << "handle " << v << " moved";
  EXPECT_LT(meanDistance(b, r.clean), meanDistance(r.noisy, r.clean));
  // An exactly isometric input needs one sweep to see it and moves nothing.
  const std::vector<Vec3> clean = r.clean;
  std::vector<Vec3> c = clean;
  const IsometryStats sc = polished.project(c);
  EXPECT_EQ(sc.lengthSweeps, 1);
  EXPECT_LT(maxDistance(c, clean), 1e-12);
  EXPECT_THROW(
      IsometryProjector(r.grid.sheet.pattern, r.grid.sheet.triangles, fixed, {.lengthSweeps = -1}),
      std::invalid_argument);
}

// Test 6: two runs give bit-identical output.
TEST(Isometry, Deterministic) {
  const NoisyRoll r = makeNoisyRoll(0.06, 0.012, 11);
  const std::vector<int> fixed{r.grid.cornerA(), r.grid.cornerB()};
  std::vector<Vec3> a = r.noisy, b = r.noisy;
  IsometryProjector first(r.grid.sheet.pattern, r.grid.sheet.triangles, fixed);
  IsometryProjector second(r.grid.sheet.pattern, r.grid.sheet.triangles, fixed);
  const IsometryStats sa = first.project(a);
  const IsometryStats sb = second.project(b);
  EXPECT_TRUE(bitwiseEqual(a, b));
  EXPECT_FALSE(bitwiseEqual(a, r.noisy));
  EXPECT_EQ(sa.meanLengthErrorAfter, sb.meanLengthErrorAfter);
  EXPECT_EQ(sa.meanDisplacement, sb.meanDisplacement);
}
