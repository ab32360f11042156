// S_P from S_G (paper Sec. 4 "Enriching the coarse mesh before simulation",
// Fig. 4; thesis 2.3.2).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <iostream>
#include <numbers>
#include <set>
#include <stdexcept>

#include "crumple/paper/enrich.hpp"

using namespace crumple;
using namespace crumple::paper;

namespace {

constexpr double kEps = 1e-12;

GeometricVertex vertexAt(const Vec2& p, int segment, bool corner = false) {
  GeometricVertex v;
  v.pattern = p;
  v.position = Vec3(p.x(), p.y(), 0.0);
  v.onBoundary = segment >= 0;
  v.corner = corner;
  v.outlineSegment = segment;
  return v;
}

void addFace(GeometricMesh& g, std::array<int, 4> v, int region) {
  GeometricFace f;
  f.v = v;
  f.region = region;
  g.faces.push_back(f);
}

Region flatRegion() { return Region{}; }

Region curvedRegion(std::vector<Ruling> rulings, int apex = -1) {
  Region r;
  r.type = mesh::RegionType::Curved;
  r.rulings = std::move(rulings);
  r.apex = apex;
  return r;
}

// An L x L sheet as one flat region: two triangles on the four corners,
// placed tilted in 3D.
GeometricMesh squareSheet(double L) {
  GeometricMesh g;
  g.outline = {Vec2(0, 0), Vec2(L, 0), Vec2(L, L), Vec2(0, L)};
  for (int i = 0; i < 4; ++i) g.vertices.push_back(vertexAt(g.outline[i], i, true));
  const Vec3 u = Vec3(1, 0, 1).normalized();
  const Vec3 w(0, 1, 0);
  for (auto& v : g.vertices)
    v.position = Vec3(0.1, 0.2, 0.3) + v.pattern.x() * u + v.pattern.y() * w;
  addFace(g, {0, 1, 2, -1}, 0);
  addFace(g, {0, 2, 3, -1}, 0);
  g.regions = {flatRegion()};
  return g;
}

// A developable fold: flat for x <= a, a cylinder of radius R for
// a <= x <= b, flat (tangent) again for x >= b. Rulings are along y.
Vec3 foldMap(const Vec2& p, double a, double b, double R) {
  const auto arc = [&](double x) {
    const double phi = (x - a) / R;
    return Vec3(a + R * std::sin(phi), p.y(), R * (1.0 - std::cos(phi)));
  };
  if (p.x() <= a) return Vec3(p.x(), p.y(), 0.0);
  if (p.x() <= b) return arc(p.x());
  const double phi = (b - a) / R;
  return arc(b) + (p.x() - b) * Vec3(std::cos(phi), 0.0, std::sin(phi));
}

// (b) 12 x 10 cm: flat [0,4] cm | curved quads between rulings x = 4, 6, 8 cm | flat [8,12] cm.
// Bottom vertices 0..4 at x = 0, 4, 6, 8, 12 cm; top vertices 5..9 above them.
GeometricMesh foldedStrip(double radius = 0.02) {
  GeometricMesh g;
  const double W = 0.12, H = 0.1;
  g.outline = {Vec2(0, 0), Vec2(W, 0), Vec2(W, H), Vec2(0, H)};
  const double xs[5] = {0.0, 0.04, 0.06, 0.08, W};
  for (int i = 0; i < 5; ++i)
    g.vertices.push_back(vertexAt({xs[i], 0.0}, i == 4 ? 1 : 0, i == 0 || i == 4));
  for (int i = 0; i < 5; ++i)
    g.vertices.push_back(vertexAt({xs[i], H}, i == 0 ? 3 : 2, i == 0 || i == 4));
  for (auto& v : g.vertices) v.position = foldMap(v.pattern, 0.04, 0.08, radius);
  g.regions = {flatRegion(), curvedRegion({{1, 6}, {2, 7}, {3, 8}}), flatRegion()};
  addFace(g, {0, 1, 6, -1}, 0);
  addFace(g, {0, 6, 5, -1}, 0);
  addFace(g, {1, 2, 7, 6}, 1);
  addFace(g, {2, 3, 8, 7}, 1);
  addFace(g, {3, 4, 9, -1}, 2);
  addFace(g, {3, 9, 8, -1}, 2);
  return g;
}

// (c) 10 x 10 cm with a singular apex A = vertex 8 at the centre: a curved fan
// A-(3,0)-(5,0)-(7,0) cm between a left and a right flat region that share
// the edge A-(5,10) cm.
GeometricMesh fanSheet() {
  GeometricMesh g;
  const double L = 0.1;
  g.outline = {Vec2(0, 0), Vec2(L, 0), Vec2(L, L), Vec2(0, L)};
  g.vertices = {vertexAt({0, 0}, 0, true), vertexAt({0.03, 0}, 0),    vertexAt({0.05, 0}, 0),
                vertexAt({0.07, 0}, 0),    vertexAt({L, 0}, 1, true), vertexAt({L, L}, 2, true),
                vertexAt({0.05, L}, 2),    vertexAt({0, L}, 3, true), vertexAt({0.05, 0.05}, -1)};
  g.vertices[8].singular = true;
  const Quat q(Eigen::AngleAxisd(0.4, Vec3(0.3, -1.0, 0.2).normalized()));
  for (auto& v : g.vertices) v.position = q * Vec3(v.pattern.x(), v.pattern.y(), 0.0);
  g.regions = {flatRegion(), curvedRegion({{8, 1}, {8, 2}, {8, 3}}, 8), flatRegion()};
  addFace(g, {0, 1, 8, -1}, 0);
  addFace(g, {0, 8, 7, -1}, 0);
  addFace(g, {7, 8, 6, -1}, 0);
  addFace(g, {8, 1, 2, -1}, 1);
  addFace(g, {8, 2, 3, -1}, 1);
  addFace(g, {3, 4, 8, -1}, 2);
  addFace(g, {4, 5, 8, -1}, 2);
  addFace(g, {8, 5, 6, -1}, 2);
  return g;
}

double triangleArea(const mesh::SheetMesh& m, const std::array<int, 3>& t) {
  const Vec2 e1 = m.pattern[t[1]] - m.pattern[t[0]];
  const Vec2 e2 = m.pattern[t[2]] - m.pattern[t[0]];
  return 0.5 * (e1.x() * e2.y() - e1.y() * e2.x());
}

double segmentDistance(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 d = b - a;
  const double t = std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * d)).norm();
}

double outlineDistance(const GeometricMesh& g, const Vec2& p) {
  double d = 1e300;
  for (std::size_t k = 0; k < g.outline.size(); ++k)
    d = std::min(d, segmentDistance(p, g.outline[k], g.outline[(k + 1) % g.outline.size()]));
  return d;
}

bool hasEdge(const mesh::SheetMesh& m, int a, int b) {
  for (const auto& e : mesh::buildEdges(m))
    if (e.v[0] == std::min(a, b) && e.v[1] == std::max(a, b)) return true;
  return false;
}

// Properties every S_P must have: valid, CCW, area of S_G, S_G vertices
// first and unchanged, samples reproduce their pattern position, consistent
// per-triangle arrays. Returns the number of vertices on the outline.
int checkCommon(const GeometricMesh& g, const PhysicalMesh& p) {
  const auto& m = p.mesh;
  EXPECT_EQ(mesh::validate(m), "");
  EXPECT_EQ(p.geometricVertexCount(), g.vertexCount());
  EXPECT_EQ(p.faceOfTriangle.size(), m.triangleCount());
  EXPECT_EQ(m.regionTypes.size(), g.regions.size());
  for (std::size_t r = 0; r < g.regions.size(); ++r) EXPECT_EQ(m.regionTypes[r], g.regions[r].type);
  for (std::size_t i = 0; i < g.vertexCount(); ++i) {
    EXPECT_EQ(m.pattern[i], g.vertices[i].pattern) << "S_G vertex " << i << " moved";
    EXPECT_EQ(m.positions[i], g.vertices[i].position) << "S_G vertex " << i << " moved";
  }
  double area = 0.0;
  for (std::size_t t = 0; t < m.triangleCount(); ++t) {
    const double a = triangleArea(m, m.triangles[t]);
    EXPECT_GT(a, 0.0) << "triangle " << t << " is not counter-clockwise";
    area += a;
    const int f = p.faceOfTriangle[t];
    EXPECT_GE(f, 0);
    if (f >= 0) {
      EXPECT_EQ(g.faces[f].region, m.regionOfTriangle[t]);
    }
  }
  EXPECT_NEAR(area, outlineArea(g), 1e-12 * outlineArea(g));
  // A sample's weights reproduce its pattern position in its face.
  for (std::size_t k = 0; k < p.samples.size(); ++k) {
    const auto& s = p.samples[k];
    const auto& face = g.faces[s.face];
    Vec2 x = Vec2::Zero();
    double sum = 0.0;
    for (int j = 0; j < face.size(); ++j) {
      x += s.weights[j] * g.vertices[face.v[j]].pattern;
      sum += s.weights[j];
      EXPECT_GE(s.weights[j], -1e-12);
    }
    EXPECT_NEAR(sum, 1.0, 1e-12);
    EXPECT_LT((x - m.pattern[g.vertexCount() + k]).norm(), kEps);
  }
  int onOutline = 0;
  for (const Vec2& x : m.pattern) onOutline += outlineDistance(g, x) < kEps ? 1 : 0;
  return onOutline;
}

int countRegionTriangles(const PhysicalMesh& p, int region) {
  return static_cast<int>(
      std::count(p.mesh.regionOfTriangle.begin(), p.mesh.regionOfTriangle.end(), region));
}

}  // namespace

// (a) One flat region: the sizing check of paper Table V.
TEST(Enrich, FlatSquareSampling) {
  const GeometricMesh g = squareSheet(0.1);
  const CrumpleParams params;
  const PhysicalMesh p = buildPhysicalMesh(g, params);
  const int boundary = checkCommon(g, p);
  const int vertices = static_cast<int>(p.mesh.vertexCount());
  const int triangles = static_cast<int>(p.mesh.triangleCount());
  std::cout << "10 cm flat sheet: S_P " << vertices << " vertices (" << boundary << " boundary, "
            << vertices - boundary << " interior), " << triangles << " triangles\n";
  RecordProperty("sp_vertices", vertices);
  RecordProperty("sp_triangles", triangles);
  // ceil(10 cm * 1.2/cm) = 12 pieces per side: 4 corners + 4 * 11 samples.
  EXPECT_EQ(boundary, 48);
  EXPECT_GE(triangles, 100);
  EXPECT_LE(triangles, 130);
  // A triangulated disc: T = 2 n_interior + n_boundary - 2.
  EXPECT_EQ(triangles, 2 * (vertices - boundary) + boundary - 2);

  const double h = 1.0 / std::sqrt(params.rhoInt);
  for (std::size_t i = g.vertexCount(); i < p.mesh.vertexCount(); ++i) {
    const Vec2& x = p.mesh.pattern[i];
    const double d = outlineDistance(g, x);
    // On the outline, or at least h/2 inside it.
    EXPECT_TRUE(d < kEps || d >= 0.5 * h * (1 - 1e-9)) << "sample " << i << " at " << d;
  }
  // Boundary edges lie on the outline, evenly spaced at <= 1/rho_bound.
  int boundaryEdges = 0;
  for (const auto& e : mesh::buildEdges(p.mesh)) {
    if (e.interior()) continue;
    ++boundaryEdges;
    const Vec2& a = p.mesh.pattern[e.v[0]];
    const Vec2& b = p.mesh.pattern[e.v[1]];
    EXPECT_LT(outlineDistance(g, 0.5 * (a + b)), kEps);
    EXPECT_NEAR((b - a).norm(), 0.1 / 12.0, 1e-12);
  }
  EXPECT_EQ(boundaryEdges, 48);
  // Isotropic sampling: no sliver.
  double minAngle = std::numbers::pi;
  for (const auto& t : p.mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const Vec2 u = p.mesh.pattern[t[(k + 1) % 3]] - p.mesh.pattern[t[k]];
      const Vec2 v = p.mesh.pattern[t[(k + 2) % 3]] - p.mesh.pattern[t[k]];
      minAngle = std::min(minAngle, std::acos(u.normalized().dot(v.normalized())));
    }
  EXPECT_GT(minAngle, 25.0 * std::numbers::pi / 180.0);
  // Positions: every sample on the tilted plane of the sheet.
  const Vec3 u = Vec3(1, 0, 1).normalized();
  for (std::size_t i = 0; i < p.mesh.vertexCount(); ++i) {
    const Vec2& x = p.mesh.pattern[i];
    const Vec3 expected = Vec3(0.1, 0.2, 0.3) + x.x() * u + x.y() * Vec3(0, 1, 0);
    EXPECT_LT((p.mesh.positions[i] - expected).norm(), kEps);
  }
}

// (a) S_G vertices inside a flat region (a handle vertex of the faces, and an
// unused one) are S_P vertices with triangles around them, away from samples.
TEST(Enrich, FlatRegionKeepsInteriorGeometricVertices) {
  const CrumpleParams params;
  const double h = 1.0 / std::sqrt(params.rhoInt);
  GeometricMesh g = squareSheet(0.1);
  GeometricVertex handle = vertexAt({0.031, 0.047}, -1);
  handle.handle = true;
  g.vertices.push_back(handle);  // vertex 4: a face vertex
  g.faces.clear();
  addFace(g, {0, 1, 4, -1}, 0);
  addFace(g, {1, 2, 4, -1}, 0);
  addFace(g, {2, 3, 4, -1}, 0);
  addFace(g, {3, 0, 4, -1}, 0);
  GeometricVertex loose = vertexAt({0.072, 0.061}, -1);
  loose.handle = true;
  g.vertices.push_back(loose);  // vertex 5: in no face
  for (auto& v : g.vertices) v.position = Vec3(v.pattern.x(), v.pattern.y(), 0.05);

  const PhysicalMesh p = buildPhysicalMesh(g, params);
  const int boundary = checkCommon(g, p);
  const int vertices = static_cast<int>(p.mesh.vertexCount());
  EXPECT_EQ(static_cast<int>(p.mesh.triangleCount()), 2 * (vertices - boundary) + boundary - 2)
      << "every vertex, the loose one included, is part of the triangulation";
  for (int v : {4, 5}) {
    EXPECT_GE(mesh::vertexNeighbours(p.mesh, v).size(), 3u) << "vertex " << v;
    for (std::size_t i = g.vertexCount(); i < p.mesh.vertexCount(); ++i)
      EXPECT_GE((p.mesh.pattern[i] - g.vertices[v].pattern).norm(), 0.5 * h * (1 - 1e-9));
  }
  // The S_G triangulation of the region is ignored: its internal edges are not constraints,
  // so the S_G edge 0-4 (to the interior vertex) is not forced into S_P.
  EXPECT_FALSE(hasEdge(p.mesh, 0, 4));
}

// (b) flat | curved quad strip | flat, parallel rulings.
TEST(Enrich, CurvedQuadsSplitAtBarycenterAndRulingsStayEdges) {
  const GeometricMesh g = foldedStrip();
  const PhysicalMesh p = buildPhysicalMesh(g, CrumpleParams{});
  checkCommon(g, p);
  const auto& m = p.mesh;
  const std::size_t n = g.vertexCount();

  for (int f : {2, 3}) {
    std::set<int> centres;
    int count = 0;
    for (std::size_t t = 0; t < m.triangleCount(); ++t) {
      if (p.faceOfTriangle[t] != f) continue;
      ++count;
      for (int v : m.triangles[t])
        if (v >= static_cast<int>(n)) centres.insert(v);
    }
    EXPECT_EQ(count, 4) << "quad " << f;
    ASSERT_EQ(centres.size(), 1u) << "quad " << f;
    const int c = *centres.begin();
    const auto& s = p.samples[c - n];
    EXPECT_EQ(s.face, f);
    for (double w : s.weights) EXPECT_EQ(w, 0.25);
    Vec2 centre = Vec2::Zero();
    Vec3 position = Vec3::Zero();
    for (int v : g.faces[f].v) {
      centre += 0.25 * g.vertices[v].pattern;
      position += 0.25 * g.vertices[v].position;
    }
    EXPECT_LT((m.pattern[c] - centre).norm(), kEps);
    EXPECT_LT((m.positions[c] - position).norm(), kEps);
  }
  EXPECT_EQ(countRegionTriangles(p, 1), 8);

  // The rulings, flat|curved borders included, are single S_P edges.
  for (auto [a, b] : {std::pair{1, 6}, std::pair{2, 7}, std::pair{3, 8}})
    EXPECT_TRUE(hasEdge(m, a, b)) << "ruling " << a << "-" << b;
  // Nothing added in the closed curved strip but the two barycenters: no
  // sample on a ruling, none on the curved region's outline edges.
  int inStrip = 0;
  for (std::size_t i = n; i < m.vertexCount(); ++i)
    if (m.pattern[i].x() > 0.04 - kEps && m.pattern[i].x() < 0.08 + kEps) ++inStrip;
  EXPECT_EQ(inStrip, 2);
  // Outline edges of the flat regions are sampled: bottom edge 0-1 (4 cm) in 5 pieces.
  int bottomLeft = 0;
  for (std::size_t i = n; i < m.vertexCount(); ++i)
    if (std::abs(m.pattern[i].y()) < kEps && m.pattern[i].x() < 0.04) ++bottomLeft;
  EXPECT_EQ(bottomLeft, 4);
  // Flat-region samples lie on the folded surface: its map is affine there.
  for (std::size_t i = n; i < m.vertexCount(); ++i) {
    if (g.regions[g.faces[p.samples[i - n].face].region].type != mesh::RegionType::Flat) continue;
    EXPECT_LT((m.positions[i] - foldMap(m.pattern[i], 0.04, 0.08, 0.02)).norm(), kEps);
  }

  // Without densities, S_P is S_G with quads split: flat regions keep their corners only.
  CrumpleParams bare;
  bare.rhoBound = 0.0;
  bare.rhoInt = 0.0;
  const PhysicalMesh q = buildPhysicalMesh(g, bare);
  checkCommon(g, q);
  EXPECT_EQ(q.mesh.vertexCount(), n + 2);
  EXPECT_EQ(q.mesh.triangleCount(), 4u + 8u);
}

// (c) A fan curved region from an interior singular apex, between two flat
// regions that share an edge from the apex.
TEST(Enrich, FanRegionAndFlatFlatEdge) {
  const GeometricMesh g = fanSheet();
  const CrumpleParams params;
  const double h = 1.0 / std::sqrt(params.rhoInt);
  const PhysicalMesh p = buildPhysicalMesh(g, params);
  checkCommon(g, p);
  const auto& m = p.mesh;
  const std::size_t n = g.vertexCount();

  // The fan's triangles are copied as they are.
  EXPECT_EQ(countRegionTriangles(p, 1), 2);
  std::set<std::array<int, 3>> fan;
  for (std::size_t t = 0; t < m.triangleCount(); ++t)
    if (m.regionOfTriangle[t] == 1) {
      auto tri = m.triangles[t];
      std::rotate(tri.begin(), std::min_element(tri.begin(), tri.end()), tri.end());
      fan.insert(tri);
    }
  EXPECT_EQ(fan, (std::set<std::array<int, 3>>{{1, 2, 8}, {2, 3, 8}}));
  // Rulings and the flat|flat edge stay single edges.
  for (int b : {1, 2, 3, 6}) EXPECT_TRUE(hasEdge(m, 8, b)) << "edge 8-" << b;
  // The apex belongs to all three regions.
  std::set<int> apexRegions;
  for (std::size_t t = 0; t < m.triangleCount(); ++t)
    for (int v : m.triangles[t])
      if (v == 8) apexRegions.insert(m.regionOfTriangle[t]);
  EXPECT_EQ(apexRegions, (std::set<int>{0, 1, 2}));
  // Every sample is in a flat region: on its outline part, or h/2 away from
  // every region border and S_G vertex.
  const std::vector<std::pair<int, int>> inner{{8, 1}, {8, 2}, {8, 3}, {8, 6}};
  for (std::size_t i = n; i < m.vertexCount(); ++i) {
    const Vec2& x = m.pattern[i];
    const auto& s = p.samples[i - n];
    EXPECT_EQ(g.regions[g.faces[s.face].region].type, mesh::RegionType::Flat);
    EXPECT_FALSE(std::abs(x.y()) < kEps && x.x() > 0.03 - kEps && x.x() < 0.07 + kEps)
        << "sample on the fan's outline edge";
    if (outlineDistance(g, x) < kEps) continue;
    for (auto [a, b] : inner)
      EXPECT_GE(segmentDistance(x, g.vertices[a].pattern, g.vertices[b].pattern),
                0.5 * h * (1 - 1e-9));
    for (const auto& v : g.vertices) EXPECT_GE((x - v.pattern).norm(), 0.5 * h * (1 - 1e-9));
  }
  // Samples lie on the (rotated) plane of the sheet.
  const Quat q(Eigen::AngleAxisd(0.4, Vec3(0.3, -1.0, 0.2).normalized()));
  for (std::size_t i = 0; i < m.vertexCount(); ++i)
    EXPECT_LT((m.positions[i] - q * Vec3(m.pattern[i].x(), m.pattern[i].y(), 0.0)).norm(), kEps);
}

// (d) Samples follow S_G's 3D state exactly (rigid motion, with velocities).
TEST(Enrich, UpdateSamplesFollowsGeometricMesh) {
  GeometricMesh g = foldedStrip();
  PhysicalMesh p = buildPhysicalMesh(g, CrumpleParams{});
  const std::vector<Vec3> before = p.mesh.positions;

  const Mat3 R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Vec3 shift(0.3, -0.1, 0.25);
  const Vec3 omega(0.5, -1.0, 2.0), v0(0.1, 0.2, -0.3);
  for (auto& v : g.vertices) {
    v.position = R * v.position + shift;
    v.velocity = v0 + omega.cross(v.position);
  }
  std::vector<Vec3> velocities;
  updateSamples(p, g, &velocities);
  ASSERT_EQ(velocities.size(), p.mesh.vertexCount());
  for (std::size_t i = 0; i < p.mesh.vertexCount(); ++i) {
    const Vec3 expected = R * before[i] + shift;
    EXPECT_LT((p.mesh.positions[i] - expected).norm(), kEps) << "vertex " << i;
    EXPECT_LT((velocities[i] - (v0 + omega.cross(expected))).norm(), 1e-12) << "vertex " << i;
  }
  EXPECT_EQ(mesh::validate(p.mesh), "");

  // A non-rigid change: unfold the sheet flat; flat-region samples follow the new map.
  for (auto& v : g.vertices) v.position = Vec3(v.pattern.x(), v.pattern.y(), 0.0);
  updateSamples(p, g);
  for (std::size_t i = 0; i < p.mesh.vertexCount(); ++i)
    EXPECT_LT(
        (p.mesh.positions[i] - Vec3(p.mesh.pattern[i].x(), p.mesh.pattern[i].y(), 0.0)).norm(),
        kEps);

  GeometricMesh other = g;
  other.vertices.pop_back();
  EXPECT_THROW(updateSamples(p, other), std::invalid_argument);
}

// (e) Identical input gives identical S_P, byte for byte; the topology and
// samples depend on the S_G pattern only.
TEST(Enrich, DeterministicAndPatternOnly) {
  const auto same = [](const PhysicalMesh& a, const PhysicalMesh& b, bool positions) {
    const auto bytesEqual = [](const auto& x, const auto& y) {
      return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(x[0])) == 0;
    };
    EXPECT_TRUE(bytesEqual(a.mesh.pattern, b.mesh.pattern));
    if (positions) {
      EXPECT_TRUE(bytesEqual(a.mesh.positions, b.mesh.positions));
    }
    EXPECT_EQ(a.mesh.triangles, b.mesh.triangles);
    EXPECT_EQ(a.mesh.regionOfTriangle, b.mesh.regionOfTriangle);
    EXPECT_EQ(a.mesh.regionTypes, b.mesh.regionTypes);
    EXPECT_EQ(a.faceOfTriangle, b.faceOfTriangle);
    ASSERT_EQ(a.samples.size(), b.samples.size());
    for (std::size_t k = 0; k < a.samples.size(); ++k) {
      EXPECT_EQ(a.samples[k].face, b.samples[k].face);
      EXPECT_EQ(std::memcmp(a.samples[k].weights.data(), b.samples[k].weights.data(),
                            sizeof(a.samples[k].weights)),
                0);
    }
  };
  const CrumpleParams params;
  for (const GeometricMesh& g : {squareSheet(0.1), foldedStrip(), fanSheet()}) {
    const PhysicalMesh a = buildPhysicalMesh(g, params);
    const PhysicalMesh b = buildPhysicalMesh(g, params);
    same(a, b, true);
  }
  // Another fold radius (another 3D state, same pattern): same topology.
  same(buildPhysicalMesh(foldedStrip(0.02), params), buildPhysicalMesh(foldedStrip(0.035), params),
       false);
}

TEST(Enrich, RejectsBadInput) {
  GeometricMesh g = squareSheet(0.1);
  g.faces[1].region = 3;
  EXPECT_THROW(buildPhysicalMesh(g, CrumpleParams{}), std::invalid_argument);
}

// Sliver hinges (CrumpleParams::sliverHingeRatio): a hinge between two thin
// triangles is softened by (A1 + A2) / |e|^2 / ratio; well-shaped hinges and
// boundary edges keep their stiffness.
TEST(Enrich, SliverHingesAreSoftenedInProportion) {
  mesh::SheetMesh sp;
  // Two hinges: a unit square split on its diagonal (ratio (0.5 + 0.5) / 2 =
  // 0.5), and a 10 x 0.1 sliver pair sharing its long edge.
  sp.pattern = {Vec2(0, 0), Vec2(1, 0),  Vec2(1, 1),   Vec2(0, 1),
                Vec2(3, 0), Vec2(13, 0), Vec2(8, 0.1), Vec2(8, -0.1)};
  sp.positions.resize(sp.pattern.size(), Vec3::Zero());
  sp.triangles = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {5, 4, 7}};
  const auto edges = mesh::buildEdges(sp);
  std::vector<mesh::MeshEdge> hinges;
  for (const auto& e : edges)
    if (e.interior()) hinges.push_back(e);
  ASSERT_EQ(hinges.size(), 2u);
  const auto factors = sliverHingeFactors(sp, hinges, 0.1);
  for (std::size_t h = 0; h < hinges.size(); ++h) {
    const bool diagonal = hinges[h].v[0] == 0;
    // Sliver: (0.5 + 0.5) / 100 = 0.01, a tenth of the ratio.
    EXPECT_NEAR(factors[h], diagonal ? 1.0 : 0.1, 1e-12) << "hinge " << h;
  }
  // A ratio of 0 switches the softening off.
  for (double f : sliverHingeFactors(sp, hinges, 0.0)) EXPECT_EQ(f, 1.0);
}
