// The path tracer's quad primitives (src/render/src/embree/quad_pairs.hpp):
// a folded strip of planar cells pairs each cell's two triangles, the
// per-corner data follows the corners' rotation, and every Embree hit on a
// quad maps back to the triangle and barycentrics of the point it hit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "embree/quad_pairs.hpp"
#include "embree/scene_build.hpp"

namespace crumple::render::pt {
namespace {

// A strip of `cells` planar quads along x, each folded by `fold` radians
// from the previous about their common edge (parallel to y), each split
// along a diagonal into two counter-clockwise triangles; corners' shading
// normals, texture coordinates (the vertex's pattern point) and singular
// bits set so that a rotation can be checked.
struct Strip {
  MeshData mesh;
  SheetLook look;
  std::vector<std::array<float, 2>> pattern;  // per vertex
};

Strip foldedStrip(int cells, float fold, float width = 0.01f, float along = 0.2f) {
  Strip s;
  s.mesh.kind = GeomKind::Sheet;
  float angle = 0.0f, x = 0.0f, z = 0.0f;
  for (int i = 0; i <= cells; ++i) {
    for (const float y : {0.0f, along}) {
      s.mesh.vertices.push_back(V3{x, y, z});
      s.pattern.push_back({width * static_cast<float>(i), y});
    }
    x += width * std::cos(angle);
    z += width * std::sin(angle);
    angle += fold;
  }
  const auto tri = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    s.mesh.triangles.push_back({a, b, c});
    const V3 n =
        cross(s.mesh.vertices[b] - s.mesh.vertices[a], s.mesh.vertices[c] - s.mesh.vertices[a]);
    s.mesh.faceNormals.push_back(n * (1.0f / length(n)));
    SheetTri& st = s.look.tris.emplace_back();
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = s.mesh.triangles.back()[k];
      st.normals[k] = V3{static_cast<float>(v), 0.0f, 0.0f};
      st.uv[2 * k] = s.pattern[v][0];
      st.uv[2 * k + 1] = s.pattern[v][1];
    }
    st.singularCorners = 1u;  // corner 0
  };
  for (std::uint32_t i = 0; i < static_cast<std::uint32_t>(cells); ++i) {
    const std::uint32_t a = 2 * i, b = 2 * i + 2, c = 2 * i + 3, d = 2 * i + 1;
    // Alternate the triangle order and start corner so that pairing must rotate.
    if (i % 2 == 0) {
      tri(a, b, c);
      tri(a, c, d);
    } else {
      tri(d, a, c);
      tri(b, c, a);
    }
  }
  return s;
}

TEST(EmbreeQuads, PairsEachPlanarCellsTwoTriangles) {
  Strip s = foldedStrip(12, 0.05f);
  const std::vector<std::array<std::uint32_t, 3>> before = s.mesh.triangles;
  pairIntoQuads(s.mesh, &s.look);
  ASSERT_EQ(s.mesh.quads.size(), 12u);
  for (std::size_t q = 0; q < 12; ++q) {
    const auto& pair = s.mesh.quadTriangles[q];
    // Triangles 2i and 2i + 1 are cell i's halves.
    EXPECT_EQ(pair[0] / 2, pair[1] / 2) << "quad " << q;
    const auto& a = s.mesh.triangles[pair[0]];
    const auto& b = s.mesh.triangles[pair[1]];
    const auto& quad = s.mesh.quads[q];
    // Embree's split: (q0, q1, q3) and (q2, q3, q1).
    EXPECT_EQ((std::array<std::uint32_t, 3>{quad[0], quad[1], quad[3]}), a);
    EXPECT_EQ((std::array<std::uint32_t, 3>{quad[2], quad[3], quad[1]}), b);
  }
  // Rotations only: each triangle keeps its corners in cyclic order, and its
  // per-corner data moved with them.
  for (std::size_t t = 0; t < before.size(); ++t) {
    const auto& now = s.mesh.triangles[t];
    int r = 0;
    while (r < 3 && now[0] != before[t][r]) ++r;
    ASSERT_LT(r, 3);
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(now[k], before[t][(k + r) % 3]);
      const SheetTri& st = s.look.tris[t];
      EXPECT_EQ(st.normals[k].x, static_cast<float>(now[k]));
      EXPECT_EQ(st.uv[2 * k], s.pattern[now[k]][0]);
      EXPECT_EQ(st.uv[2 * k + 1], s.pattern[now[k]][1]);
      EXPECT_EQ((st.singularCorners >> k) & 1u, now[k] == before[t][0] ? 1u : 0u);
    }
  }
}

TEST(EmbreeQuads, LoneAndInconsistentTrianglesStayTriangles) {
  Strip s = foldedStrip(3, 0.3f);
  // Turn triangle 0 over: its neighbours across its edges no longer pair with it.
  std::swap(s.mesh.triangles[0][1], s.mesh.triangles[0][2]);
  s.mesh.faceNormals[0] = -s.mesh.faceNormals[0];
  s.look.tris.clear();
  pairIntoQuads(s.mesh, nullptr);
  std::size_t lone = 0, covered = 0;
  for (std::size_t q = 0; q < s.mesh.quads.size(); ++q) {
    const auto& pair = s.mesh.quadTriangles[q];
    covered += pair[1] == MeshData::kNoTriangle ? 1 : 2;
    if (pair[1] == MeshData::kNoTriangle) {
      ++lone;
      EXPECT_EQ(s.mesh.quads[q][3], s.mesh.quads[q][2]);
    }
    if (pair[0] == 0 || pair[1] == 0) {
      EXPECT_EQ(pair[1], MeshData::kNoTriangle) << "turned over";
    }
  }
  EXPECT_EQ(covered, s.mesh.triangles.size());
  EXPECT_GE(lone, 2u);  // triangle 0 and its cell's other half
}

// Embree's hits on the quads, each at a known point of a known triangle,
// map back (triangleHit) to that triangle and point.
TEST(EmbreeQuads, EveryHitMapsBackToItsTriangleAndPoint) {
  Strip s = foldedStrip(16, 0.2f, 0.02f, 0.1f);
  pairIntoQuads(s.mesh, &s.look);
  FrameData f;
  f.meshes.push_back(s.mesh);
  f.sheet = s.look;
  EmbreeDevice device;
  const ScenePtr scene = buildScene(device, f, false);
  const MeshData& m = f.meshes.front();
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  const float bary[][2] = {{0.2f, 0.3f}, {0.6f, 0.1f}, {0.1f, 0.7f}, {0.33f, 0.33f}};
  int hits = 0;
  for (std::uint32_t t = 0; t < m.triangles.size(); ++t)
    for (const auto& b : bary) {
      const V3 p0 = m.vertices[m.triangles[t][0]], p1 = m.vertices[m.triangles[t][1]],
               p2 = m.vertices[m.triangles[t][2]];
      const V3 target = p0 + (p1 - p0) * b[0] + (p2 - p0) * b[1];
      const V3 n = m.faceNormals[t];
      RTCRayHit rh{};
      const V3 org = target + n * 0.001f;
      rh.ray.org_x = org.x;
      rh.ray.org_y = org.y;
      rh.ray.org_z = org.z;
      rh.ray.dir_x = -n.x;
      rh.ray.dir_y = -n.y;
      rh.ray.dir_z = -n.z;
      rh.ray.tfar = 1.0f;
      rh.ray.mask = 0xFFFFFFFFu;
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(scene.get(), &context, &rh);
      ASSERT_NE(rh.hit.geomID, RTC_INVALID_GEOMETRY_ID) << "triangle " << t;
      const TriangleHit h = triangleHit(m, rh.hit.primID, rh.hit.u, rh.hit.v);
      EXPECT_EQ(h.triangle, t);
      EXPECT_NEAR(h.u, b[0], 1e-4f) << "triangle " << t;
      EXPECT_NEAR(h.v, b[1], 1e-4f) << "triangle " << t;
      ++hits;
    }
  EXPECT_EQ(hits, 4 * 32);
}

}  // namespace
}  // namespace crumple::render::pt
